"""``servohydraulics identify REC.csv [REC2.csv ...] --mode ... --out DIR``: a rig
identified from lab records (docs/lab-records.md)."""

from __future__ import annotations

import argparse

from .. import _core

MR_LAW_NAMES = dict(_core.MR_LAW_NAMES)


def _run(args: argparse.Namespace) -> int:
    from ..identification import identify
    from ..identification.checks import check_accept
    from ..identification.law import parse_values
    from ..readers import layout_of
    from .compare import print_checks

    accept = check_accept(args.accept)
    layout = layout_of(args)
    fit = [k.strip() for k in args.fit.split(",") if k.strip()] if args.fit else None
    if args.current is not None and args.voltage is not None:
        raise ValueError("invalid --current and --voltage together: an MR damper's law reads one field input; "
                         "give --current (amperes) or --voltage (volts)")
    currents = None if args.current is None else parse_values(args.current, "--current")
    voltages = None if args.voltage is None else parse_values(args.voltage, "--voltage")
    ident = identify(args.records, rig=args.rig, fit=fit, mode=args.mode, specimen=args.specimen, dt=args.dt,
                     max_nfev=args.max_nfev, progress=not args.quiet, layout=layout, accept=accept,
                     currents=currents, voltages=voltages, law=args.law)
    report = ident.write(args.out)
    for k in ident.keys:
        lo, hi = ident.intervals[k]
        print(f"  {k} = {ident.values[k]:.5g} [{lo:.5g}, {hi:.5g}] (95 %)")
    for f in ident.flags:
        print(f"  note: {f}")
    print_checks(ident.checks)
    for b, a in zip(ident.before, ident.after):
        print(f"  {a.name}: " + ", ".join(f"{c} NRMSE {b.nrmse(c):.2f} % -> {a.nrmse(c):.2f} %" for c in a.channels))
    print(f"wrote {args.out}/rig_identified.toml, identification.json, {report.name} "
          f"({ident.runtime_s['total']:.1f} s)")
    return 0


def register(sub) -> None:
    from ..readers import add_arguments
    from .compare import add_accept

    p = sub.add_parser("identify", help="identify a rig from its own lab records (two-stage fit, intervals, plots)")
    p.add_argument("records", nargs="+", help="record file(s) of the same rig (CSV or other text, DAQ export, .mat)")
    p.add_argument("--mode", required=True, choices=["displacement", "force"], help="control mode of the records")
    p.add_argument("--rig", default=None, help="start rig TOML (default: a generic rig scaled from the record)")
    p.add_argument("--fit", default=None, help="comma-separated rig keys to fit (default: loop + specimen keys)")
    p.add_argument("--specimen", default=None, choices=["linear", "bouc_wen", "mr_damper"],
                   help="specimen model whose keys are fitted: linear (k, c), bouc_wen (bouc_wen_hysteresis), "
                        "mr_damper (Spencer's MR damper); default linear (mr_damper with --current/--voltage)")
    p.add_argument("--current", default=None, metavar="I1,I2,...",
                   help="an MR damper's coil current [A] per record, in order: one rig fitted to all, the damper's "
                        "field law across them (docs/lab-records.md)")
    p.add_argument("--voltage", default=None, metavar="U1,U2,...",
                   help="the same for a voltage-driven MR damper [V]")
    p.add_argument("--law", default=None, choices=sorted(MR_LAW_NAMES),
                   help="the MR damper's field law: spencer (linear, default) or quiroz2022 (the UTFSM thesis': alpha "
                        "quadratic, Bouc-Wen beta, gamma decaying exponentially); with --current/--voltage")
    p.add_argument("--dt", type=float, default=None, help="controller sample time [s] (default: the record's)")
    p.add_argument("--max-nfev", type=int, default=60, help="time-domain evaluations budget (default: 60)")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_accept(p)
    add_arguments(p)
    p.set_defaults(func=_run)
