"""``servohydraulics marths-benchmark``: the virtual multi-axial RTHS benchmark (maRTHS, Condori Uribe et
al. 2023) with RoDeAC or another multi-actuator compensator, on the benchmark's data folder."""

from __future__ import annotations


def _run(args) -> int:
    from ..atomic import check_folder
    from ..marths.report import check_perturbed, execute, j_table, prepare, write_outputs
    from ..workers import check_workers

    if args.workers is not None:
        check_workers(args.workers, "--workers")  # before anything runs
    perturbed = check_perturbed(args.perturbed, "--perturbed")
    if args.seed < 0:
        raise ValueError(f"invalid --seed = {args.seed}: expected a whole number >= 0")
    setup = prepare(args.data, args.record, args.controller, perturbed, args.seed, workers=args.workers,
                    daq_quantizer=args.daq_quantizer, daq_saturation=args.daq_saturation,
                    exact_kinematics=args.exact_kinematics,
                    plant=args.plant)  # every input validated: nothing written yet
    check_folder(args.out)  # a folder that cannot hold the results fails before the runs
    run = execute(setup, progress=not args.quiet)
    out = write_outputs(run, args.out)
    print(j_table(run["results"]))
    nom = run["results"]["runs"]["nominal"]
    print(f"peak command voltages {nom['peak_voltage_V'][0]:.3f} V, {nom['peak_voltage_V'][1]:.3f} V: "
          f"{'realizable' if nom['realizable'] else 'NOT realizable'}")
    print(f"wrote {out / 'results.json'}, {out / 'report.md'} and the plots")
    return 0


def register(sub) -> None:
    from ..marths.benchmark import CONTROLLERS
    from ..marths.data import RECORDS

    p = sub.add_parser("marths-benchmark",
                       help="the multi-axial RTHS benchmark (maRTHS, Condori Uribe et al. 2023): J1-J10")
    p.add_argument("--data", required=True, help="the benchmark's data folder (e.g. ../shared/marths-data)")
    p.add_argument("--record", default="elcentro",
                   help="ground motion: " + " | ".join(RECORDS) + " (default: elcentro)")
    p.add_argument("--controller", default="rodeac", metavar="NAME | module:Class",
                   help="multi-actuator compensator: a built-in (" + ", ".join(CONTROLLERS) + "; default: rodeac) "
                        "or your own as module:Class, imported from PYTHONPATH and built with no arguments, with "
                        "reset() and command(desired, measured[, desired_velocity=, desired_acceleration=]) -> "
                        "the two commands [m] (docs/marths-benchmark.md)")
    p.add_argument("--plant", default="identified", metavar="identified | nonlinear | RIG.toml",
                   help="behind the actuators: the benchmark's identified linear plant (default), the nonlinear "
                        "two-actuator rig calibrated to it, or your multi-actuator rig file (docs/multi-actuator.md); "
                        "on a nonlinear rig the report adds its spools, forces and force fighting")
    p.add_argument("--perturbed", default="0", help="perturbed-plant trials after the nominal one (default: 0)")
    p.add_argument("--seed", type=int, default=123,
                   help="noise seed of the nominal trial (default 123, the benchmark's) and the seed of the perturbed "
                        "plants and their noise")
    p.add_argument("--workers", type=int, default=None,
                   help="processes for the perturbed trials, 1 .. the processors (default: all)")
    p.add_argument("--daq-quantizer", action="store_true",
                   help="quantise the command voltage to 2^-18 V (the scripts' DAQ block; off in the model)")
    p.add_argument("--daq-saturation", action="store_true",
                   help="saturate the command voltage at +-3.8 V (the scripts' DAQ block; off in the model)")
    p.add_argument("--exact-kinematics", action="store_true",
                   help="the exact actuator -> frame inverse instead of the model's estimate")
    p.add_argument("--out", required=True, help="output folder (results.json, report.md, plots)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_run)
