"""``servohydraulics serve``: this project's rig as a site that OpenSees' genericClient
element or OpenFresco drives over TCP (docs/distributed.md)."""

from __future__ import annotations


def _run(args) -> int:
    import logging
    import signal
    import sys
    from pathlib import Path

    from ..distributed.server import Server
    from ..distributed.site import make_site
    from ..rig import load_rig, zhao2003

    logging.basicConfig(level=logging.INFO, stream=sys.stderr, format="%(asctime)s serve: %(message)s")
    rig = load_rig(args.rig) if args.rig else zhao2003()
    if args.actuators < 1:
        raise ValueError(f"invalid --actuators = {args.actuators}: expected >= 1")
    if args.max_clients is not None and args.max_clients < 1:
        raise ValueError(f"invalid --max-clients = {args.max_clients}: expected >= 1")
    if args.actuator == "ideal" and (args.realtime or args.controller != "none" or args.record):
        raise ValueError("--realtime, --controller and --record need --actuator model (the ideal actuator has no "
                         "dynamics)")
    options = {}
    if args.actuator == "model":
        options = {"dt": args.dt, "controller": args.controller, "step_samples": args.step_samples,
                   "pacer": _pacer(args) if args.realtime else None}
    site = make_site(rig, args.actuator, args.actuators, **options)
    if args.record:
        Path(args.record).mkdir(parents=True, exist_ok=True)
    server = Server(site, args.port, bind=args.bind, timeout=args.timeout, quickack=not args.no_quickack,
                    record=args.record)
    # Ctrl-C (SIGINT) and SIGTERM stop it cleanly.  SIGINT explicitly: a process started in the
    # background of a shell without job control inherits SIGINT ignored, and Python then installs
    # no handler, so `kill -INT` would never reach the server.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    server.serve(max_clients=args.max_clients, on_ready=lambda: print(f"listening on {server.address[0]}:"
                                                                       f"{server.port}", flush=True))
    return 0


def _pacer(args):
    """The wall-clock pacing of --realtime (servohydraulics.realtime), one period per controller sample."""
    from .. import _core

    try:
        from ..realtime import Pacer  # imported only here: the realtime path's own module
    except ImportError as e:
        raise ValueError(f"--realtime needs servohydraulics.realtime (the pacing module), not importable here: {e}") \
            from None

    dt = args.dt if args.dt is not None else _core.RpsdConfig().dt
    return Pacer(dt, fifo_priority=args.fifo_priority, cpu=args.cpu, lock_memory=args.lock_memory)


def register(sub) -> None:
    p = sub.add_parser("serve", help="host the rig's actuator(s) and specimen as a site for OpenSees (genericClient) "
                                     "or OpenFresco over TCP")
    p.add_argument("--rig", help="rig TOML file (default: the calibrated Zhao 2003 preset)")
    p.add_argument("--port", type=int, required=True, help="TCP port (0: any free port, printed)")
    p.add_argument("--bind", default="127.0.0.1",
                   help="address to listen on (default: 127.0.0.1, this machine only; 0.0.0.0 opens it to the network)")
    p.add_argument("--actuator", choices=["model", "ideal"], default="model",
                   help="model (default): the rig's actuator, servovalve and servo controller track each trial "
                        "displacement; ideal: the specimen follows it exactly")
    p.add_argument("--controller", choices=["none", "lead"], default="none",
                   help="compensation on the displacement command (model only): none (default) or lead, the "
                        "paper's amplitude compensation T_d = 68 ms")
    p.add_argument("--actuators", type=int, default=1,
                   help="actuators of the site, each with its own copy of the rig's specimen (the client's "
                        "displacement size must equal it; default 1)")
    p.add_argument("--dt", type=float, default=None, help="controller sample time [s] (model; default 0.5 ms)")
    p.add_argument("--step-samples", type=int, default=None,
                   help="controller samples per trial that does not advance the time channel (default: as many as "
                        "the last step that did, or 1)")
    p.add_argument("--timeout", type=float, default=60.0, help="seconds a client may stay silent (default 60)")
    p.add_argument("--max-clients", type=int, default=None, help="stop after serving this many clients")
    p.add_argument("--record", default=None,
                   help="folder: write each client's controller samples (time, command, displacement, force) to "
                        "client_NNN.csv there (model actuator)")
    p.add_argument("--no-quickack", action="store_true",
                   help="leave the kernel's delayed ACK on (to measure the stall it causes with OpenSees' Nagle)")
    p.add_argument("--realtime", action="store_true",
                   help="pace every controller sample to the wall clock (CLOCK_MONOTONIC deadlines)")
    p.add_argument("--fifo-priority", type=int, default=None, help="--realtime: SCHED_FIFO priority, if permitted")
    p.add_argument("--cpu", type=int, default=None, help="--realtime: pin to this CPU, if permitted")
    p.add_argument("--lock-memory", action="store_true", help="--realtime: mlockall, if permitted")
    p.set_defaults(func=_run)
