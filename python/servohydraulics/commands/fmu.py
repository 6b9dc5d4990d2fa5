"""``servohydraulics fmu``: export the plant or a controller as an FMI 2.0 co-simulation FMU."""

from __future__ import annotations


def _value(text: str):
    """A --set value: an int, a float, or the text (an option name such as nonlinear)."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def _config(items: list[str], kind: str) -> dict:
    from ..fmu import settings

    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ValueError(f"invalid --set {item!r}: expected NAME=VALUE, e.g. compensation=nonlinear")
        if key.strip() not in settings(kind):
            raise ValueError(f"invalid --set {item!r}: the {kind} takes "
                             + (f"one of {settings(kind)}" if settings(kind) else "no settings"))
        out[key.strip()] = _value(value.strip())
    return out


def _run(args) -> int:
    from ..fmu import export_fmu
    from ..rig import load_rig, zhao2003
    from ..simulate import solver_options

    rig = load_rig(args.rig) if args.rig else zhao2003()
    path = export_fmu(rig, args.out, kind=args.kind, mode=args.mode, dt=args.dt, x0=args.x0,
                      solver_options=solver_options(args.method), name=args.name, **_config(args.set, args.kind))
    print(f"wrote {path} ({args.kind}, FMI 2.0 co-simulation, linux64)")
    return 0


def register(sub) -> None:
    from ..fmu import KINDS
    from ..simulate import DEFAULT_METHOD, METHODS, MODES

    p = sub.add_parser("fmu", help="export the plant or the EFT/RPsD controller as an FMI 2.0 co-simulation FMU")
    p.add_argument("--rig", help="rig TOML file (default: the calibrated Zhao 2003 preset)")
    p.add_argument("--kind", choices=KINDS, default=KINDS[0],
                   help="the plant, or a controller (EFT drives force control, RPsD displacement control)")
    p.add_argument("--mode", choices=list(MODES), default=None,
                   help="the plant's control mode: the command in m (displacement) or N (default displacement)")
    p.add_argument("--out", required=True, help="the .fmu file to write")
    p.add_argument("--dt", type=float, default=None, help="controller sample [s] (default 0.0005)")
    p.add_argument("--x0", type=float, default=0.0, help="the plant's initial displacement [m]")
    p.add_argument("--method", choices=list(METHODS), default=DEFAULT_METHOD,
                   help=f"the plant's ODE integrator (default: the library's, {DEFAULT_METHOD})")
    p.add_argument("--name", default=None, help="modelIdentifier (default servohydraulics_<kind>)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a controller setting as run_eft / run_rpsd take it (repeatable), e.g. compensation=nonlinear")
    p.set_defaults(func=_run)
