"""Command line: ``servohydraulics <command> ...``.  A thin dispatcher: each
command's work lives in its own module."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from .simulate import MODES


def _demo(args: argparse.Namespace) -> int:
    from .paper.demo import run_demo

    run_demo(out=args.out, quick=args.quick)
    return 0


def _simulate(args: argparse.Namespace) -> int:
    from .excitations import sine
    from .rig import load_rig, zhao2003
    from .simulate import simulate

    rig = load_rig(args.rig) if args.rig else zhao2003()
    command = sine(args.amplitude, args.frequency, args.duration, args.dt)
    res = simulate(rig, mode=args.mode, command=command, dt=args.dt, x0=args.x0)
    res.to_csv(args.out)
    for w in res.warnings():
        print("warning:", w, file=sys.stderr)
    print(f"wrote {args.out}: {len(res)} rows, {res.work.internal_steps} integrator steps")
    return 0


def _reproduce(args: argparse.Namespace) -> int:
    from .paper.reproduce import reproduce
    from .workers import check_workers

    if args.workers is not None:
        check_workers(args.workers, "--workers")
    rep = reproduce(out=args.out, quick=args.quick, workers=args.workers)
    print(f"wrote {args.out}/reproduction.md: {rep.agree_count} of {len(rep.rows)} rows agree, "
          f"{len(rep.figures)} figures, {rep.runtime:.1f} s")
    return 0


def _diagnose(args: argparse.Namespace) -> int:
    from .commands.compare import print_checks
    from .diagnosis import diagnose
    from .identification.checks import check_accept
    from .readers import layout_of
    from .rig import load_rig

    accept = check_accept(args.accept)
    layout = layout_of(args)
    names = [c.strip() for c in args.candidates.split(",") if c.strip()] if args.candidates else None
    d = diagnose(args.records, load_rig(args.rig), mode=args.mode, progress=not args.quiet, candidates=names,
                 dt=args.dt, layout=layout, accept=accept)
    d.write(args.out)
    print_checks(d.checks)
    print(f"{d.verdict}: {d.summary}")
    for e in d.effects:
        pars = ", ".join(f"{k} = {v['value']:.4g} {v['unit']}" for k, v in e["parameters"].items()
                         if v["value"] is not None)
        print(f"  + {e['name']}: {pars}")
    print("  gap (normalised RMS): " + ", ".join(f"{c} {100 * d.gap_before[c]:.2f} % -> {100 * d.gap_after[c]:.2f} %"
                                                  for c in d.gap_before))
    print(f"wrote {args.out}/diagnosis.json, rig_updated.toml, report.md ({d.runtime_s:.1f} s)")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="servohydraulics", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)

    d = sub.add_parser("demo", help="the main job: simulate the paper's rig on built-in defaults, plot, summarise")
    d.add_argument("--out", default="demo_out", help="output directory (default: demo_out)")
    d.add_argument("--quick", action="store_true", help="shorter records")
    d.set_defaults(func=_demo)

    s = sub.add_parser("simulate", help="simulate a sine command and write the record CSV")
    s.add_argument("--rig", help="rig TOML file (default: the calibrated Zhao 2003 preset)")
    s.add_argument("--mode", choices=list(MODES), default="displacement")
    s.add_argument("--amplitude", type=float, default=0.00127, help="command amplitude [m or N]")
    s.add_argument("--frequency", type=float, default=1.0, help="command frequency [Hz]")
    s.add_argument("--duration", type=float, default=5.0, help="[s]")
    s.add_argument("--dt", type=float, default=0.0005, help="controller sample time [s]")
    s.add_argument("--x0", type=float, default=0.0, help="initial displacement [m]")
    s.add_argument("--out", required=True, help="record CSV to write")
    s.set_defaults(func=_simulate)

    r = sub.add_parser("reproduce", help="regenerate the paper's figures and reproduction.md (paper vs ours)")
    r.add_argument("--out", default="reproduction", help="output directory (default: reproduction)")
    r.add_argument("--quick", action="store_true", help="shorter sweeps (a faster, coarser table)")
    r.add_argument("--workers", type=int, default=None,
                   help="parallel processes for the sections, 1 .. the processors (default: 2)")
    r.set_defaults(func=_reproduce)
    g = sub.add_parser("diagnose", help="name the effect the model is missing in lab records, fit it, show the gap")
    g.add_argument("records", nargs="+", help="record file(s) of the same rig (time, command, displacement, force): "
                                          "CSV or other text, a DAQ export (--layout), .mat")
    g.add_argument("--rig", required=True, help="the nominal rig TOML file")
    g.add_argument("--mode", required=True, choices=list(MODES),
                   help="control mode of the records")
    g.add_argument("--out", required=True, help="output directory (diagnosis.json, rig_updated.toml, report.md)")
    g.add_argument("--candidates", help="restrict the library to these candidates (comma-separated names)")
    g.add_argument("--quiet", action="store_true", help="no progress bar")
    g.add_argument("--dt", type=float, default=None,
                   help="controller sample time [s] (default: the record's; a 1 kHz record of a 2 kHz rig: 0.0005)")
    from .commands.compare import add_accept
    from .readers import add_arguments

    add_accept(g)
    add_arguments(g)
    g.set_defaults(func=_diagnose)

    from .commands import register_all  # commands that live in their own module (commands/*.py)

    register_all(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Runs a command.  Exit codes: 0 done, 1 the run failed (a solver failure or
    an internal error), 2 bad input or a file that cannot be read or written,
    130 interrupted; every failure is one line on stderr, never a traceback
    (``SERVOHYDRAULICS_DEBUG=1`` re-raises for a traceback)."""
    args = build_parser().parse_args(argv)
    where = f"servohydraulics {args.command}"
    try:
        return int(args.func(args) or 0)
    except Exception as e:  # noqa: BLE001 - the one place that turns any failure into a message
        if os.environ.get("SERVOHYDRAULICS_DEBUG"):
            raise
        code, text = _failure(e)
        print(f"{where}: error: {text}", file=sys.stderr)
        return code
    except KeyboardInterrupt:
        print(f"{where}: interrupted", file=sys.stderr)
        return 130


def _failure(e: Exception) -> tuple[int, str]:
    """(exit code, one-line message) of an exception escaping a command."""
    from .response import SimulationError

    text = " ".join(str(e).split()) or type(e).__name__
    if isinstance(e, (ValueError, OSError)):  # bad input; files (OSError messages name the file)
        if isinstance(e, OSError) and e.filename and str(e.filename) not in text:
            text = f"{e.filename}: {text}"
        return 2, text
    if isinstance(e, SimulationError):
        return 1, text
    return 1, f"internal error ({type(e).__name__}: {text}); please report it with the command line"


if __name__ == "__main__":
    sys.exit(main())
