"""Randomized accuracy of the integrators on random valid rigs (issue 16):

    python3 evaluation/accuracy_random_rigs.py --rigs 1200 --json evaluation/accuracy_random_rigs.json

Each rig is drawn (fixed seed) from wide, physically valid ranges around the
calibrated preset (mass, stiffness, damping, friction with or without LuGre,
piston area, compressibility, leakage, supply pressure, valve gain and
bandwidth, controller gain, conversion factors), in displacement or force
control, under a sine command plus a step whose size is a random fraction of
what the rig can deliver (stroke, or p_s A).  Every run is compared with the
tight-tolerance reference: CVODE at rtol 1e-10 with the rig-scaled absolute
tolerances.  Error: the larger of max |x - x_ref| / max |x_ref| and the same
for the load-cell force.  A run is

- ``within``: error <= the method's stated tolerance (TOLERANCE);
- ``flagged``: not within, but the run says so: a non-ok status, or RK4
  samples flagged inaccurate by its error estimate;
- ``silent``: not within and nothing said: a silent wrong answer (must be 0).

Rigs whose reference run fails are counted and skipped.  The "before" numbers
of docs/benchmarks.md come from running this script against the core of the
starting commit (no dopri5, no RK4 flag: the old default is CVODE with fixed
absolute tolerances, the old RK4 rule is unflagged):

    SERVOHYDRAULICS_CORE_DIR=<old core> python3 evaluation/accuracy_random_rigs.py --rigs 1200

tests/python/test_accuracy.py runs the same check on fewer, shorter runs.
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


def random_rig(sh, rng: np.random.Generator):
    """A random valid rig: every parameter drawn in a wide range around the preset."""
    r = sh.zhao2003()
    r.m = _log_uniform(rng, 50.0, 20000.0)
    r.k = _log_uniform(rng, 1e4, 1e7)
    r.k_2 = r.k * rng.uniform(0.3, 1.0)
    r.c = 2.0 * rng.uniform(0.005, 0.1) * math.sqrt(r.k * r.m)
    r.F_c = 0.0 if rng.random() < 0.2 else _log_uniform(rng, 1.0, 2000.0)
    r.effects.lugre_friction = bool(rng.random() < 0.2)
    r.A = _log_uniform(rng, 2e-3, 5e-2)
    r.K_a = _log_uniform(rng, 3e-13, 1e-11)
    r.C_l = _log_uniform(rng, 1e-12, 1e-10)
    r.p_s = _log_uniform(rng, 7e6, 3e7)
    r.K_v = _log_uniform(rng, 2e-3, 5e-2)
    r.K_s = _log_uniform(rng, 0.02, 1.0)
    r.f_v = _log_uniform(rng, 20.0, 200.0)
    r.zeta_v = rng.uniform(0.5, 1.2)
    r.G_p = _log_uniform(rng, 0.3, 4.0)
    r.C_F_disp = _log_uniform(rng, 20.0, 200.0)
    r.C_F_force = _log_uniform(rng, 1e-5, 5e-4)
    r.effects.servovalve_dynamics = bool(rng.random() < 0.9)
    return r


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


def _options(sh, which: str, rtol: float | None = None):
    methods = sh.simulate.__globals__["METHODS"]
    if which == "reference":
        return sh.solver_options(method="cvode", rtol=1e-10, max_steps_per_sample=100000)
    kw = {} if rtol is None else {"rtol": rtol}
    if which == "default":
        return sh.solver_options(**kw) if "dopri5" in methods else sh.solver_options(method="cvode", **kw)
    return sh.solver_options(method="rk4")


def _error(r, ref) -> float:
    n = min(len(r.time), len(ref.time))
    ex = np.max(np.abs(r.displacement[:n] - ref.displacement[:n])) / max(np.max(np.abs(ref.displacement)), 1e-12)
    ef = np.max(np.abs(r.force[:n] - ref.force[:n])) / max(np.max(np.abs(ref.force)), 1e-12)
    return float(max(ex, ef))


def run_case(sh, rig, mode: str, u: np.ndarray, dt: float, rtol: float | None = None) -> dict:
    """The reference and each method on one case: error, status, flags, time."""
    try:
        ref = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, "reference"), raise_on_failure=False)
    except ValueError as e:  # e.g. RK4's automatic rule refusing the rig is per method; this is setup
        return {"reference": f"error: {e}"}
    if not ref.success:
        return {"reference": ref.status}
    out: dict = {"reference": "ok"}
    for which in ("default", "rk4"):
        try:
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
    return out


def survey(sh, rigs: int, seed: int = 16, duration: float = 1.0, dt: float = 5e-4, progress: bool = True,
           rtol: float | None = None) -> dict:
    """Runs `rigs` random cases and counts within / flagged / silent per method."""
    from tqdm import tqdm

    rng = np.random.default_rng(seed)
    counts = {w: {"within": 0, "flagged": 0, "silent": 0, "worst_silent": 0.0, "silent_cases": []}
              for w in ("default", "rk4")}
    skipped = 0
    for i in tqdm(range(rigs), disable=not progress, desc="random rigs"):
        rig, mode, u = random_case(sh, rng, duration, dt)
        res = run_case(sh, rig, mode, u, dt, rtol)
        if res["reference"] != "ok":
            skipped += 1
            continue
        for which in ("default", "rk4"):
            r, c = res[which], counts[which]
            if r["within"]:
                c["within"] += 1
            elif r["flagged"]:
                c["flagged"] += 1
            else:
                c["silent"] += 1
                c["worst_silent"] = max(c["worst_silent"], r["error"])
                c["silent_cases"].append({"index": i, "mode": mode, "error": r["error"]})
    return {"rigs": rigs, "seed": seed, "duration_s": duration, "dt_s": dt, "tolerance": TOLERANCE, "rtol": rtol,
            "reference_failed": skipped, "counts": counts}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rigs", type=int, default=1200)
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--duration", type=float, default=1.0, help="record length [s]")
    ap.add_argument("--rtol", type=float, default=None, help="rtol of the default method (None: its default)")
    ap.add_argument("--json", default="", help="write the counts here")
    ap.add_argument("--no-progress", action="store_true")
    args = ap.parse_args(argv)
    if "servohydraulics" not in sys.modules and not any(Path(p, "servohydraulics").is_dir() for p in sys.path if p):
        sys.path.insert(0, str(ROOT / "python"))  # this tree's Python layer unless PYTHONPATH gives one
    import servohydraulics as sh

    res = survey(sh, args.rigs, args.seed, args.duration, progress=not args.no_progress, rtol=args.rtol)
    print(json.dumps(res, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
