"""Randomized accuracy of the integrators on random valid rigs (issues 16 and 26):

    python3 evaluation/accuracy_random_rigs.py --family wide --rigs 400 --json evaluation/accuracy_wide_rigs.json

Three families of rigs, drawn with a fixed seed:

- ``random`` (issue 16): wide, physically valid ranges around the calibrated preset (mass,
  stiffness, damping, friction with or without LuGre, piston area, compressibility, leakage,
  supply pressure, valve gain and bandwidth, controller gain, conversion factors);
- ``wide`` (issue 26): the same keys over several decades (mass 1 kg-100 t, stiffness 1e3-1e8 N/m,
  area 2 cm^2-0.1 m^2, compressibility 1e-14-1e-10 m^5/N, valve gain 1e-3-0.3, loop gain 0.1-30,
  force conversion 1e-6-1e-3 V/N, ...);
- ``high_gain`` (issue 26): the random family with a loop gain of 5-500, a strong valve and stiff
  oil (compressibility down to 1e-14 m^5/N), where the default's stiff fallback missed by up to 47 %.

Each rig runs in displacement or force control under a sine command plus a step whose size is a
random fraction of what the rig can deliver (stroke, or p_s A).  Every run is compared with a
tight-tolerance reference: ARKODE's explicit Dormand-Prince pair (no Newton iteration, no
Jacobian: independent of the default's CVODE fallback; ``--reference cvode`` for CVODE) at rtol
1e-10 with absolute tolerances a tenth of the default's scales.  Error: the larger of
max |x - x_ref| / max |x_ref| and the same for the load-cell force.  A run is

- ``within``: error <= the method's stated tolerance (TOLERANCE);
- ``flagged``: not within, but the run says so: a non-ok status, or samples flagged inaccurate
  (RK4's error estimate; the default's check of its stiff samples);
- ``silent``: not within and nothing said: a silent wrong answer (must be 0).

``flagged_within`` counts the false alarms (within, yet flagged); the flag's precision is
flagged / (flagged + flagged_within), its recall flagged / (flagged + silent).  Each reference is
confirmed by the other one (CVODE at the same tolerances): a rig where they differ by more than
REFERENCE_AGREEMENT is counted under ``reference_uncertain`` and skipped, as are rigs whose
reference run fails; RK4 is skipped on a rig whose automatic rule needs
more than RK4_MAX_SUBSTEPS substeps per sample (counted).  The "before" numbers of
docs/benchmarks.md come from running this script against the core of the starting commit:

    SERVOHYDRAULICS_CORE_DIR=<old core> python3 evaluation/accuracy_random_rigs.py --family wide ...

``--rk4-flag-rtols 5e-5,2e-4`` reruns RK4 at each flag tolerance (same states, only its flag
differs) and counts the flag's precision and recall at each (``rk4_flag_sweep``): how the default
``rk4_flag_rtol`` was calibrated (docs/benchmarks.md).

tests/python/test_accuracy.py runs the same check on fewer, shorter runs, and an oracle test on
two high-gain rigs.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

#: The stated accuracy of each method [-] (relative to the peak of x and of F).
TOLERANCE = {"default": 1e-3, "rk4": 1e-2}


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


#: Each family's draw ranges, in the order they are drawn (log-uniform unless noted; the order
#: fixes the seeded draws, so the committed results stay reproducible).
RANDOM_RANGES = dict(m=(50.0, 20000.0), k=(1e4, 1e7), zeta=(0.005, 0.1), F_c_off=0.2, F_c=(1.0, 2000.0),
                     A=(2e-3, 5e-2), K_a=(3e-13, 1e-11), C_l=(1e-12, 1e-10), p_s=(7e6, 3e7), K_v=(2e-3, 5e-2),
                     K_s=(0.02, 1.0), f_v=(20.0, 200.0), G_p=(0.3, 4.0), C_F_disp=(20.0, 200.0),
                     C_F_force=(1e-5, 5e-4), valve_on=0.9)
WIDE_RANGES = dict(m=(1.0, 1e5), k=(1e3, 1e8), zeta=(0.005, 0.2), F_c_off=0.3, F_c=(1.0, 5000.0),
                   A=(2e-4, 1e-1), K_a=(1e-14, 1e-10), C_l=(1e-13, 1e-9), p_s=(3e6, 3e7), K_v=(1e-3, 3e-1),
                   K_s=(0.01, 3.0), f_v=(10.0, 300.0), G_p=(0.1, 30.0), C_F_disp=(10.0, 300.0),
                   C_F_force=(1e-6, 1e-3), valve_on=0.8)


def _draw_rig(sh, rng: np.random.Generator, R: dict):
    r = sh.zhao2003()
    r.m = _log_uniform(rng, *R["m"])
    r.k = _log_uniform(rng, *R["k"])
    r.k_2 = r.k * rng.uniform(0.3, 1.0)
    r.c = 2.0 * rng.uniform(*R["zeta"]) * math.sqrt(r.k * r.m)
    r.F_c = 0.0 if rng.random() < R["F_c_off"] else _log_uniform(rng, *R["F_c"])
    r.effects.lugre_friction = bool(rng.random() < 0.2)
    for key in ("A", "K_a", "C_l", "p_s", "K_v", "K_s", "f_v"):
        setattr(r, key, _log_uniform(rng, *R[key]))
    r.zeta_v = rng.uniform(0.5, 1.2)
    for key in ("G_p", "C_F_disp", "C_F_force"):
        setattr(r, key, _log_uniform(rng, *R[key]))
    r.effects.servovalve_dynamics = bool(rng.random() < R["valve_on"])
    return r


def random_rig(sh, rng: np.random.Generator):
    """A random valid rig: every parameter drawn in a wide range around the preset."""
    return _draw_rig(sh, rng, RANDOM_RANGES)


def random_case(sh, rng: np.random.Generator, duration: float, dt: float):
    """(rig, mode, command): a sine of random amplitude and frequency plus a held step."""
    rig = random_rig(sh, rng)
    mode = "force" if rng.random() < 0.5 else "displacement"
    scale = rig.stroke if mode == "displacement" else rig.p_s * rig.A
    t = np.arange(int(round(duration / dt)) + 1) * dt
    amp = scale * _log_uniform(rng, 0.01, 0.5)
    u = amp * np.sin(2 * np.pi * _log_uniform(rng, 0.5, 10.0) * t)
    u[t >= 0.6 * duration] += scale * rng.uniform(-0.3, 0.3)
    return rig, mode, u


def wide_rig(sh, rng: np.random.Generator):
    """A random valid rig drawn over several decades (issue 26): mass, stiffness, piston area,
    compressibility, leakage, valve gains, loop gain and conversion factors far beyond the preset."""
    return _draw_rig(sh, rng, WIDE_RANGES)


def high_gain_rig(sh, rng: np.random.Generator):
    """A rig of the random family with a high loop gain, a strong valve and stiff oil (issue 26:
    where the default's stiff fallback missed its tolerance by up to 47 %)."""
    r = random_rig(sh, rng)
    r.G_p = _log_uniform(rng, 5.0, 500.0)
    r.K_v = _log_uniform(rng, 1e-2, 3e-1)
    r.K_s = _log_uniform(rng, 0.1, 5.0)
    r.K_a = _log_uniform(rng, 1e-14, 3e-12)
    r.m = _log_uniform(rng, 1.0, 2000.0)
    r.C_F_force = _log_uniform(rng, 1e-4, 1e-2)
    return r


#: The rig families: "random" (issue 16's draw, around the preset), "wide" and "high_gain" (issue 26).
FAMILIES = {"random": random_rig, "wide": wide_rig, "high_gain": high_gain_rig}


def family_case(sh, rng: np.random.Generator, duration: float, dt: float, family: str = "random"):
    """(rig, mode, command) of a family: the command as random_case's."""
    if family == "random":
        return random_case(sh, rng, duration, dt)
    rig = FAMILIES[family](sh, rng)
    mode = "force" if rng.random() < 0.5 else "displacement"
    scale = rig.stroke if mode == "displacement" else rig.p_s * rig.A
    t = np.arange(int(round(duration / dt)) + 1) * dt
    amp = scale * _log_uniform(rng, 0.01, 0.5)
    u = amp * np.sin(2 * np.pi * _log_uniform(rng, 0.5, 10.0) * t)
    u[t >= 0.6 * duration] += scale * rng.uniform(-0.3, 0.3)
    return rig, mode, u


#: The references: ARKODE's explicit Dormand-Prince pair (no Newton, no Jacobian: independent of the
#: default's CVODE fallback) or CVODE, at rtol 1e-10 with absolute tolerances a tenth of the default's.
REFERENCES = ("arkode_erk", "cvode")
#: Each run's reference is confirmed by the other one: they must agree to this (relative to the peaks).
REFERENCE_AGREEMENT = 0.1 * min(TOLERANCE.values())

#: RK4 is not run on a rig whose automatic rule needs more substeps per sample than this (the
#: evaluation's cost; such a rig is counted under "rk4_skipped").
RK4_MAX_SUBSTEPS = 4000


def _options(sh, which: str, rtol: float | None = None, reference: str = "arkode_erk",
             flag_rtol: float | None = None):
    methods = sh.simulate.__globals__["METHODS"]
    if which == "reference":
        return sh.solver_options(method=reference, rtol=1e-10, atol_fraction=1e-3, max_steps_per_sample=1000000)
    kw = {} if rtol is None else {"rtol": rtol}
    if which == "default":
        return sh.solver_options(**kw) if "dopri5" in methods else sh.solver_options(method="cvode", **kw)
    return sh.solver_options(method="rk4", **({} if flag_rtol is None else {"rk4_flag_rtol": flag_rtol}))


def _error(r, ref) -> float:
    n = min(len(r.time), len(ref.time))
    ex = np.max(np.abs(r.displacement[:n] - ref.displacement[:n])) / max(np.max(np.abs(ref.displacement)), 1e-12)
    ef = np.max(np.abs(r.force[:n] - ref.force[:n])) / max(np.max(np.abs(ref.force)), 1e-12)
    return float(max(ex, ef))


def _rk4_substeps(sh, rig, mode: str, dt: float) -> int:
    core = sh.simulate.__globals__["_core"]
    return int(core.rk4_automatic_substeps(core.Dynamics(rig, sh.simulate.__globals__["MODES"][mode]), dt,
                                           sh.solver_options(method="rk4")))


def run_case(sh, rig, mode: str, u: np.ndarray, dt: float, rtol: float | None = None,
             reference: str = "arkode_erk", methods: tuple = ("default", "rk4"), flag_rtols: tuple = ()) -> dict:
    """The reference and each method on one case: error, status, flags, time; RK4 is also run at each
    of `flag_rtols` (its flag's tolerance: same states, only the flag differs) to calibrate it."""
    try:
        ref = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, "reference", reference=reference),
                          raise_on_failure=False)
        other = next(r for r in REFERENCES if r != reference)
        check = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, "reference", reference=other),
                            raise_on_failure=False)
    except ValueError as e:  # an invalid rig: setup, not a wrong answer
        return {"reference": f"error: {e}"}
    if not ref.success or not check.success:
        return {"reference": ref.status if not ref.success else f"{other}: {check.status}"}
    # The two references must agree to a tenth of the tightest tolerance: where they do not (a rig
    # that amplifies even a 1e-10 tolerance's error past 1e-4), no run can be judged against them.
    gap = _error(check, ref)
    if not gap <= REFERENCE_AGREEMENT:
        return {"reference": f"uncertain: {other} departs from {reference} by {gap:.2e}"}
    out: dict = {"reference": "ok"}
    for which in methods:
        try:
            if which == "rk4" and _rk4_substeps(sh, rig, mode, dt) > RK4_MAX_SUBSTEPS:
                out[which] = {"skipped": True}
                continue
            t0 = time.perf_counter()
            r = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, which, rtol), raise_on_failure=False)
            wall = time.perf_counter() - t0
        except ValueError as e:  # refused at construction: a clear error is a status, not a wrong answer
            out[which] = {"error": math.nan, "status": f"refused: {e}", "flagged": True, "within": False}
            continue
        err = _error(r, ref) if r.success else math.nan
        flagged = (not r.success) or getattr(r.work, "inaccurate_samples", 0) > 0
        out[which] = {"error": err, "status": r.status, "flagged": bool(flagged),
                      "within": bool(r.success and err <= TOLERANCE[which]),
                      "stiff_samples": int(getattr(r.work, "stiff_samples", 0)),
                      "inaccurate_samples": int(getattr(r.work, "inaccurate_samples", 0)), "wall_s": wall}
        if which == "rk4":
            out[which]["flag_sweep"] = {}
            for fr in flag_rtols:
                rf = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, which, flag_rtol=fr), raise_on_failure=False)
                out[which]["flag_sweep"][fr] = bool((not rf.success) or rf.work.inaccurate_samples > 0)
    return out


def _new_counts() -> dict:
    return {"within": 0, "flagged": 0, "silent": 0, "worst_silent": 0.0, "worst": 0.0, "silent_cases": [],
            "flagged_within": 0, "skipped": 0, "wall_s": 0.0}


def _finish_counts(c: dict) -> None:
    """Precision and recall of the run's flag as a detector of a miss (error > tolerance)."""
    tp, fn, fp = c["flagged"], c["silent"], c["flagged_within"]
    c["flag_precision"] = tp / (tp + fp) if tp + fp else None
    c["flag_recall"] = tp / (tp + fn) if tp + fn else None
    c["flag_rate_within"] = fp / c["within"] if c["within"] else None


def survey(sh, rigs: int, seed: int = 16, duration: float = 1.0, dt: float = 5e-4, progress: bool = True,
           rtol: float | None = None, family: str = "random", reference: str = "arkode_erk",
           methods: tuple = ("default", "rk4"), flag_rtols: tuple = ()) -> dict:
    """Runs `rigs` random cases of a family and counts within / flagged / silent per method, the
    flag's false alarms (flagged_within) and its precision and recall; for RK4 also at each of
    `flag_rtols` (rk4_flag_sweep)."""
    from tqdm import tqdm

    rng = np.random.default_rng(seed)
    counts = {w: _new_counts() for w in methods}
    sweep = {fr: _new_counts() for fr in flag_rtols}
    skipped, uncertain, cases = 0, 0, []
    for i in tqdm(range(rigs), disable=not progress, desc=f"{family} rigs"):
        rig, mode, u = family_case(sh, rng, duration, dt, family)
        res = run_case(sh, rig, mode, u, dt, rtol, reference, methods, flag_rtols)
        if res["reference"] != "ok":
            skipped += 1
            uncertain += res["reference"].startswith("uncertain")
            continue
        cases.append([i, mode] + [[res[w].get("error"), res[w].get("flagged"), res[w].get("stiff_samples")]
                                  for w in methods])
        for which in methods:
            r, c = res[which], counts[which]
            if r.get("skipped"):
                c["skipped"] += 1
                continue
            c["wall_s"] += r.get("wall_s", 0.0)
            if math.isfinite(r["error"]):
                c["worst"] = max(c["worst"], r["error"])
            if r["within"]:
                c["within"] += 1
                c["flagged_within"] += int(r["flagged"])
            elif r["flagged"]:
                c["flagged"] += 1
            else:
                c["silent"] += 1
                c["worst_silent"] = max(c["worst_silent"], r["error"])
                c["silent_cases"].append({"index": i, "mode": mode, "error": r["error"],
                                          "stiff_samples": r["stiff_samples"]})
            for fr, flagged in r.get("flag_sweep", {}).items():
                s = sweep[fr]
                key = ("flagged_within" if flagged else "") if r["within"] else ("flagged" if flagged else "silent")
                s["within"] += int(r["within"])
                if key:
                    s[key] += 1
    for c in list(counts.values()) + list(sweep.values()):
        _finish_counts(c)
    return {"family": family, "rigs": rigs, "seed": seed, "duration_s": duration, "dt_s": dt,
            "tolerance": TOLERANCE, "rtol": rtol, "reference": reference, "reference_failed": skipped,
            "reference_uncertain": uncertain, "counts": counts,
            "rk4_flag_sweep": {str(fr): {k: s[k] for k in ("within", "flagged", "silent", "flagged_within",
                                                           "flag_precision", "flag_recall", "flag_rate_within")}
                               for fr, s in sweep.items()},
            "cases": {"columns": ["index", "mode"] + [f"{w}: [error, flagged, stiff samples]" for w in methods],
                      "rows": cases}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rigs", type=int, default=1200)
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--duration", type=float, default=1.0, help="record length [s]")
    ap.add_argument("--rtol", type=float, default=None, help="rtol of the default method (None: its default)")
    ap.add_argument("--family", choices=sorted(FAMILIES), default="random", help="the rigs drawn")
    ap.add_argument("--reference", choices=REFERENCES, default="arkode_erk")
    ap.add_argument("--methods", default="default,rk4", help="comma-separated: default, rk4")
    ap.add_argument("--rk4-flag-rtols", default="",
                    help="comma-separated rk4_flag_rtol values: RK4's flag counted at each (calibration)")
    ap.add_argument("--json", default="", help="write the counts here")
    ap.add_argument("--no-progress", action="store_true")
    args = ap.parse_args(argv)
    if "servohydraulics" not in sys.modules and not any(Path(p, "servohydraulics").is_dir() for p in sys.path if p):
        sys.path.insert(0, str(ROOT / "python"))  # this tree's Python layer unless PYTHONPATH gives one
    import servohydraulics as sh

    methods = tuple(m for m in args.methods.split(",") if m)
    bad = [m for m in methods if m not in TOLERANCE]
    if bad or not methods:
        ap.error(f"invalid --methods = {args.methods!r}: expected a comma-separated subset of {sorted(TOLERANCE)}")
    res = survey(sh, args.rigs, args.seed, args.duration, progress=not args.no_progress, rtol=args.rtol,
                 family=args.family, reference=args.reference, methods=methods,
                 flag_rtols=tuple(float(v) for v in args.rk4_flag_rtols.split(",") if v))
    print(json.dumps(res, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
