"""How the diagnosed model's displacement gap on a UTFSM record moves with the actuator's size (docs/diagnose.md,
issue 25 item 2, the May runs).

    python studies/utfsm_area_displacement.py [--run may_0A_to_1A] [--out build/utfsm25] [--ratios 1,3.33,33.3]
                                              [--fit-loop-area 30,5] [--area-max 1000] [--with-supply]
                                              [--refit-damper 0.01,0.001]

Reads the diagnosed rig of an ``evaluation/utfsm_diagnose.py --run LABEL --out OUT`` run (OUT/LABEL/
rig_updated.toml), re-sizes its actuator by each ratio with the diagnosis' own load term
(``effects.apply_area``: A with K_v, K_a, C_l and F_cap, the loop's no-load response kept, what a force costs
the displacement scaled by 1 / A) and prints the displacement and force gaps (rms(measured - simulated) /
rms(measured), the record's command alone driving the model, the initial displacement refined as the
diagnosis does) on the run's diagnosed record, beside the nominal rig's.  A ratio of 1 is the diagnosed model
itself; large ratios take the load coupling away (an ideal displacement source with the same no-load loop).

``--fit-loop-area STARTS``: then the loop (K_v, f_v, zeta_v) and A fitted together on the displacement channel
alone, the diagnosed damper held, from each start of A (multiples of the nominal rig's A, the loop at the
diagnosed rig's values), by the diagnosis' own fit (``engine.fit``, the force channel weighted 0): whether any
setting of the loop and the load term gives the nominal model's displacement back.  ``--area-max R``: A's
upper bound in that fit, R times the nominal rig's A, instead of the diagnosis' own (``effects`` load term A).
``--with-supply``: the supply pressure p_s fitted too (the other load term, over its own span).

``--refit-damper LAMBDAS``: then the loop (K_v, f_v, zeta_v), the load terms (p_s, A) and the damper's force
law (its alpha, c0, c1 and gamma) fitted together from the diagnosed rig, each key in log coordinates within a
factor e^3 of its start, to the displacement residual with the force residual weighted by sqrt(lambda)
(``scipy.optimize.least_squares``, forward differences): the trade between the two channels, for each lambda.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"


def main() -> None:
    sys.path.insert(0, str(ROOT / "evaluation"))
    from utfsm_diagnose import RUNS

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import apply_area
    from servohydraulics.records import read_record

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--run", default="may_0A_to_1A", choices=[r[0] for r in RUNS])
    p.add_argument("--out", default="build/utfsm25", help="the runs' folder (OUT of utfsm_diagnose.py --run)")
    p.add_argument("--ratios", default="1,3.33,33.3", help="comma-separated multiples of the diagnosed area")
    p.add_argument("--fit-loop-area", metavar="STARTS", default="",
                   help="comma-separated starts of A (multiples of the nominal's) for a fit of the loop with A")
    p.add_argument("--area-max", type=float, default=None, metavar="R",
                   help="A's upper bound in --fit-loop-area, R times the nominal's (default: the diagnosis' own)")
    p.add_argument("--with-supply", action="store_true", help="fit the supply pressure p_s with the loop and A")
    p.add_argument("--refit-damper", metavar="LAMBDAS", default="",
                   help="comma-separated weights of the force channel for a re-fit of the loop, load terms and damper")
    a = p.parse_args()
    if a.area_max is not None and not a.area_max > 0:
        p.error(f"--area-max {a.area_max!r}: must be > 0")

    def numbers(flag: str, text: str) -> list[float]:
        try:
            out = [float(v) for v in text.split(",")] if text else []
        except ValueError:
            p.error(f"{flag} {text!r}: not comma-separated numbers")
        if any(not v > 0 for v in out):
            p.error(f"{flag} {text!r}: each must be > 0")
        return out

    ratios, starts = numbers("--ratios", a.ratios), numbers("--fit-loop-area", a.fit_loop_area)
    lambdas = numbers("--refit-damper", a.refit_damper)
    if not ratios:
        p.error("--ratios '': give at least one ratio")
    label, rig_from, record = next(r for r in RUNS if r[0] == a.run)
    diagnosed = Path(a.out) / label / "rig_updated.toml"
    if not diagnosed.exists():
        p.error(f"{diagnosed} is absent: run `python evaluation/utfsm_diagnose.py --run {label} --end 0 --out {a.out}`")
    path = DATA / f"{record}.csv"
    if not path.exists():
        p.error(f"record {path} is absent: the UTFSM data live in ../shared/real-data (or $SH_SHARED_DIR)")
    rig = sh.load_rig(diagnosed)
    nominal = sh.load_rig(ROOT / "evaluation" / "utfsm_rigs" / f"identified_from_{rig_from}.toml")
    cases = [engine.make_case(read_record(path), "displacement", record)]

    def gaps(r) -> dict:
        x0 = engine.refine_x0(r, cases, 0.0)
        return engine.gap(engine.simulate_all(r, cases, 0.0, x0), cases)

    g = gaps(nominal)
    print(f"{label}: `{record}` through the rig of `{rig_from}` (displacement / force gap, %)")
    print("| model | A / nominal A | displacement | force |\n|---|---|---|---|")
    print(f"| nominal | 1 | {100 * g['displacement']:.2f} | {100 * g['force']:.1f} |")
    for q in ratios:
        r = apply_area(rig, rig.A * q) if q != 1.0 else rig
        g = gaps(r)
        print(f"| diagnosed, A x{q:g} | {r.A / nominal.A:.3g} | {100 * g['displacement']:.2f} | "
              f"{100 * g['force']:.1f} |", flush=True)
    if starts:
        fit_loop_area(rig, nominal, cases, starts, a.area_max, a.with_supply)
    for lam in lambdas:
        refit_damper(rig, cases, lam)


def fit_loop_area(rig, nominal, cases: list, starts: list[float], area_max: float | None = None,
                  with_supply: bool = False) -> None:
    """The loop and A fitted on the displacement alone from each start of A (see the module docstring)."""
    from servohydraulics.diagnosis import engine, workflow
    from servohydraulics.diagnosis.joint import LOOP

    x0 = engine.refine_x0(rig, cases, 0.0)
    sims = engine.simulate_all(rig, cases, 0.0, x0)
    setup = workflow._Setup(nominal, "displacement", cases, [], workflow.KEEP, True, True)
    ctx = workflow._context(setup, workflow._State(rig=rig, tau=0.0, x0=tuple(x0), sims=sims))
    space = engine.Space(LOOP, ctx, ((("p_s", "Pa"),) if with_supply else ()) + (("A", "m^2"),))
    if area_max is not None:  # A is fitted as 1 / A: its upper bound is the reciprocal's lower one
        space.lo[-1] = 1.0 / (area_max * nominal.A)
    weights = {(c.name, ch): 0.0 for c in cases for ch in c.meas if ch != "displacement"}
    print(f"\nthe loop and A fitted on the displacement, p_s {'fitted too' if with_supply else 'held'}:\n"
          "| start A / nominal A | fitted A / nominal A (bound) | p_s [MPa] | K_v | f_v [Hz] | zeta_v | displacement "
          "| force | fit |\n|---|---|---|---|---|---|---|---|---|")
    for start in starts:
        t0 = time.time()
        z0 = space.absent.copy()
        z0[-1] = 1.0 / (start * nominal.A)  # A is fitted as 1 / A (its range reaches "no load coupling")
        res = engine.fit(space, cases, z0, 0.0, "all", x0, max_nfev=30, weights=weights)
        rig1, tau1 = space.rig_and_tau(res.z, 0.0)
        g = engine.gap(engine.simulate_all(rig1, cases, tau1, res.x0), cases)
        bound = 1.0 / (space.lo[-1] * nominal.A)
        print(f"| {start:g} | {rig1.A / nominal.A:.3g} ({bound:.3g}) | {1e-6 * rig1.p_s:.4g} | {rig1.K_v:.4g} | "
              f"{rig1.f_v:.4g} | {rig1.zeta_v:.3g} | {100 * g['displacement']:.3f} | {100 * g['force']:.2f} | "
              f"{time.time() - t0:.0f} s, {res.nfev} evaluations |", flush=True)


#: the keys --refit-damper moves: the loop, the load terms and the damper's force law
REFIT_KEYS = ("K_v", "f_v", "zeta_v", "p_s", "A", "mr_alpha_a", "mr_c0_a", "mr_c1_a", "mr_gamma")


def refit_damper(rig, cases: list, lam: float) -> None:
    """``REFIT_KEYS`` fitted to the displacement with the force weighted by sqrt(lam) (see the module docstring)."""
    import copy

    import numpy as np
    from scipy.optimize import least_squares

    from servohydraulics.diagnosis import engine
    from servohydraulics.response import SimulationError

    x0 = engine.refine_x0(rig, cases, 0.0)
    base = np.array([getattr(rig, k) for k in REFIT_KEYS], dtype=float)
    meas = {ch: np.concatenate([np.asarray(c.meas[ch], dtype=float) for c in cases])
            for ch in ("displacement", "force")}
    scale = {ch: float(np.sqrt(np.mean(v ** 2)) * np.sqrt(v.size)) for ch, v in meas.items()}

    def rig_at(z: np.ndarray):
        r = copy.deepcopy(rig)
        for k, b, zz in zip(REFIT_KEYS, base, z):
            setattr(r, k, float(b * np.exp(zz)))
        return r

    def residual(z: np.ndarray) -> np.ndarray:
        try:
            sims = engine.simulate_all(rig_at(z), cases, 0.0, x0)
        except (ValueError, SimulationError):  # a key combination the model refuses or cannot run
            return np.full(2 * meas["displacement"].size, 1.0)
        sim = {ch: np.concatenate([np.asarray(s[ch], dtype=float) for s in sims]) for ch in meas}
        return np.concatenate([(sim["displacement"] - meas["displacement"]) / scale["displacement"],
                               np.sqrt(lam) * (sim["force"] - meas["force"]) / scale["force"]])

    t0 = time.time()
    sol = least_squares(residual, np.zeros(len(REFIT_KEYS)), bounds=(-3.0, 3.0), method="trf", diff_step=1e-3,
                        ftol=1e-4, xtol=1e-6, max_nfev=40)
    r1 = rig_at(sol.x)
    g = engine.gap(engine.simulate_all(r1, cases, 0.0, engine.refine_x0(r1, cases, 0.0)), cases)
    values = ", ".join(f"{k} {getattr(r1, k):.4g}" for k in REFIT_KEYS)
    print(f"\nre-fit with the force weighted by sqrt({lam:g}): displacement {100 * g['displacement']:.3f} %, force "
          f"{100 * g['force']:.2f} % ({time.time() - t0:.0f} s, {sol.nfev} evaluations)\n  {values}", flush=True)


if __name__ == "__main__":
    main()
