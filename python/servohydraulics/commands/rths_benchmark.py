"""``servohydraulics rths-benchmark``: the RTHS benchmark control problem of
Silva et al. (2020) on the official data files (or the labelled embedded default)."""

from __future__ import annotations


def _run(args) -> int:
    from ..rths.data import RECORDS
    from ..rths.report import run_benchmark, write_outputs
    from ..workers import check_workers
    if args.workers is not None:
        check_workers(args.workers, "--workers")  # before anything runs: 100000 was a fork bomb
    if args.data is None:
        motion = "the benchmark's chirp" if args.record == "chirp" else "a synthetic ground motion"
        print("rths-benchmark: no --data: running the EMBEDDED DEFAULT (published structure parameters, "
              f"{motion}): NOT the benchmark's records or results")
    if args.record not in RECORDS and args.record != "chirp":
        raise ValueError(f"invalid --record = {args.record!r}: expected one of {sorted(RECORDS) + ['chirp']}")
    run = run_benchmark(args.data, args.record, args.cases, args.controller, args.perturbed, args.seed,
                        workers=args.workers, progress=not args.quiet, csi=args.csi, noise=args.noise)
    out = write_outputs(run, args.out)
    from ..rths.report import j_table
    print(j_table(run["results"]))
    print(f"wrote {out / 'results.json'}, {out / 'report.md'}")
    return 0


def register(sub) -> None:
    from ..rths.benchmark import CONTROLLERS
    p = sub.add_parser("rths-benchmark", help="the RTHS benchmark (Silva et al. 2020): J1-J9 and PSI per case")
    p.add_argument("--data", default=None,
                   help="folder with the official files ('RTHS code RT V23/' layout or a flat folder of "
                        "Case_N.mat and the records); omitted: the embedded default with a synthetic ground motion")
    p.add_argument("--record", default="elcentro",
                   help="elcentro | kobe | morganhill | chirp (default: elcentro; chirp: the benchmark's 0.1-40 Hz "
                        "verification sweep, generated)")
    p.add_argument("--cases", default="1,2,3,4", help="comma-separated cases (default: 1,2,3,4)")
    p.add_argument("--controller", default="sample", metavar="NAME | module:Class",
                   help="tracking controller: a built-in (" + ", ".join(CONTROLLERS) + "; default: the benchmark's "
                        "sample controller) or your own as module:Class, the module imported from PYTHONPATH and the "
                        "class built with no arguments, with reset() and command(desired, desired_velocity, "
                        "desired_acceleration, measured, measured_force[, measured_velocity=, "
                        "measured_pressure=]) -> command [m] "
                        "(docs/rths-benchmark.md, 'Bring your own controller')")
    p.add_argument("--perturbed", type=int, default=0, help="perturbed plants per case (default: 0)")
    p.add_argument("--seed", type=int, default=0, help="seed of the noise and of the perturbations (default: 0; with "
                        "--noise simulink, seed 0 is the official run's noise realisation)")
    p.add_argument("--noise", default="simulink", choices=["simulink", "mersenne"],
                   help="sensor-noise generator: simulink (default; the algorithm of Simulink's Random Number block "
                        "in the official SENSORS subsystem) or mersenne (a 64-bit Mersenne twister)")
    p.add_argument("--workers", type=int, default=None,
                   help="processes for the perturbed runs, 1 .. the processors (default: all)")
    p.add_argument("--csi", default="exact", choices=["exact", "derivative-block"],
                   help="control-structure interaction: exact a2 dx/dt (default, the spec's) or the official code's "
                        "Simulink Derivative block")
    p.add_argument("--out", required=True, help="output folder (results.json, report.md, plots)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_run)
