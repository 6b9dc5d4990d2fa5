"""``servohydraulics compare REC --rig RIG.toml --mode ... --out DIR``: a record's
command simulated through a rig, NRMSE and FRF per channel (docs/lab-records.md)."""

from __future__ import annotations

import argparse
import sys


def print_checks(checks) -> None:
    """Every check not acknowledged, one ``warning: FILE: [code] ...`` line each on stderr."""
    from ..identification.checks import shown

    for c in shown(checks):
        print("warning:", c.line(), file=sys.stderr)


def _run(args: argparse.Namespace) -> int:
    from ..identification import compare
    from ..identification.checks import check_accept
    from ..identification.law import field_value
    from ..readers import layout_of
    from ..records import read_record
    from ..rig import load_rig
    from ..simulate import solver_options

    accept = check_accept(args.accept)
    if args.current is not None and args.voltage is not None:
        raise ValueError("invalid --current and --voltage together: an MR damper's law reads one field input; "
                         "give --current (amperes) or --voltage (volts)")
    current = None if args.current is None else field_value(args.current, "--current")
    voltage = None if args.voltage is None else field_value(args.voltage, "--voltage")
    rec = read_record(args.record, layout_of(args))
    options = None if args.method is None else solver_options(method=args.method)
    c = compare(rec, load_rig(args.rig), args.mode, dt=args.dt, options=options, accept=accept, current=current,
                voltage=voltage)
    path = c.write(args.out)
    print_checks(c.checks)
    for ch, m in c.channels.items():
        print(f"{c.name} {ch}: NRMSE {m['nrmse_pct']:.2f} % (error mean removed: {m['nrmse_demeaned_pct']:.2f} %)")
    print(f"wrote {path}, " + ", ".join(f"{n}.png" for n in c.figure_names()))
    return 0


def add_accept(p) -> None:
    p.add_argument("--accept", default=None, metavar="CODE[,CODE]",
                   help="acknowledge warning-level checks by code (docs/lab-records.md, 'Checks'): they stay in the "
                        "JSON, marked acknowledged, and leave the screen")


def register(sub) -> None:
    from ..readers import add_arguments
    from ..simulate import METHODS

    p = sub.add_parser("compare", help="simulate a record's command through a rig and compare (NRMSE, FRF, plots)")
    p.add_argument("record", help="record file: CSV or other delimited text, a DAQ export (--layout), or .mat")
    p.add_argument("--rig", required=True, help="rig TOML file")
    p.add_argument("--mode", required=True, choices=["displacement", "force"], help="control mode of the record")
    p.add_argument("--out", required=True, help="output directory (comparison.json, overlay.png, frf.png, loops.png)")
    p.add_argument("--dt", type=float, default=None,
                   help="controller sample time [s] (default: the record's sample time)")
    p.add_argument("--method", choices=list(METHODS), default=None,
                   help="integrator (default: compare's reference, cvode)")
    p.add_argument("--current", default=None, metavar="AMPS",
                   help="the MR damper's coil current [A] of the record: the rig's field law predicts the damper "
                        "there (a value outside the law's identified range is reported as an extrapolation)")
    p.add_argument("--voltage", default=None, metavar="VOLTS", help="the same for a voltage-driven MR damper [V]")
    add_accept(p)
    add_arguments(p)
    p.set_defaults(func=_run)
