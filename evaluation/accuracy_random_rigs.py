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
- ``flagged``: not within, but the run says so: a non-ok status, or the run's accuracy check over
  its bound (``work.error_estimate`` > 1: RK4's companion at twice the substeps, the default's
  shadow at rtol / 10 of a run that turned stiff; measured against the run's peaks; a core
  without it: any sample flagged inaccurate);
- ``silent``: not within and nothing said: a silent wrong answer (must be 0).

``flagged_within`` counts the false alarms (within, yet flagged); the flag's precision is
flagged / (flagged + flagged_within), its recall flagged / (flagged + silent).  The per-sample
flags (``work.inaccurate_samples``, each against the peak up to its sample) are counted too:
``sample_flagged_within`` is the accurate runs with a flagged sample.  Each reference is
confirmed by the other one (CVODE at the same tolerances): a rig where they differ by more than
REFERENCE_AGREEMENT is counted under ``reference_uncertain`` and skipped, as are rigs whose
reference run fails; RK4 is skipped on a rig whose automatic rule needs
more than RK4_MAX_SUBSTEPS substeps per sample (counted).  The "before" numbers of
docs/benchmarks.md come from running this script against the core of the starting commit:

    SERVOHYDRAULICS_CORE_DIR=<old core> python3 evaluation/accuracy_random_rigs.py --family wide ...

``--flag-scales 0.5,1,2`` counts each method's flag as if its bound were that many times the
configured one (the check's gap scales with the bound, so no rerun: flagged iff
``work.error_estimate`` > scale; ``flag_sweep``): how the bounds were calibrated (docs/benchmarks.md).
``--cache DIR`` keeps each case's references in DIR (keyed by family, seed, index, duration, dt,
reference, checked against a digest of the case), so a run against another core reuses them.

tests/python/test_accuracy.py runs the same check on fewer, shorter runs, and an oracle test on
two high-gain rigs.
"""

from __future__ import annotations

import argparse
import hashlib
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


def _options(sh, which: str, rtol: float | None = None, reference: str = "arkode_erk"):
    methods = sh.simulate.__globals__["METHODS"]
    if which == "reference":
        return sh.solver_options(method=reference, rtol=1e-10, atol_fraction=1e-3, max_steps_per_sample=1000000)
    kw = {} if rtol is None else {"rtol": rtol}
    if which == "default":
        return sh.solver_options(**kw) if "dopri5" in methods else sh.solver_options(method="cvode", **kw)
    return sh.solver_options(method="rk4")


def _error(r, ref) -> float:
    n = min(len(r.time), len(ref.time))
    ex = np.max(np.abs(r.displacement[:n] - ref.displacement[:n])) / max(np.max(np.abs(ref.displacement)), 1e-12)
    ef = np.max(np.abs(r.force[:n] - ref.force[:n])) / max(np.max(np.abs(ref.force)), 1e-12)
    return float(max(ex, ef))


def _rk4_substeps(sh, rig, mode: str, dt: float) -> int:
    core = sh.simulate.__globals__["_core"]
    return int(core.rk4_automatic_substeps(core.Dynamics(rig, sh.simulate.__globals__["MODES"][mode]), dt,
                                           sh.solver_options(method="rk4")))


def _flag_measure(r) -> float:
    """The run's verdict on itself: inf for a failed run, its accuracy check over the bound
    (work.error_estimate: > 1 flagged; a NaN counts as flagged), or for a core without it 2.0 if any
    sample was flagged inaccurate, else 0."""
    if not r.success:
        return math.inf
    est = getattr(r.work, "error_estimate", None)
    if est is None:
        return 2.0 if r.work.inaccurate_samples > 0 else 0.0
    return math.inf if math.isnan(est) else float(est)


def _references(sh, rig, mode: str, u: np.ndarray, dt: float, reference: str, cache: Path | None, key: str):
    """(status, x_ref, F_ref): the reference's displacement and force if it ran and its check agrees."""
    digest = hashlib.sha256((repr(rig) + mode + str(dt) + reference).encode() + u.tobytes()).hexdigest()[:16]
    f = cache / f"{key}.npz" if cache else None
    if f is not None and f.exists():
        z = np.load(f)
        if str(z["digest"]) == digest:
            return str(z["status"]), z["x"], z["F"]
    x = F = np.zeros(0)
    try:
        ref = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, "reference", reference=reference),
                          raise_on_failure=False)
        other = next(r for r in REFERENCES if r != reference)
        check = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, "reference", reference=other),
                            raise_on_failure=False)
        if not ref.success or not check.success:
            status = ref.status if not ref.success else f"{other}: {check.status}"
        else:
            # The two references must agree to a tenth of the tightest tolerance: where they do not (a
            # rig that amplifies even a 1e-10 tolerance's error past 1e-4), no run can be judged against them.
            gap = _error(check, ref)
            status = "ok" if gap <= REFERENCE_AGREEMENT else f"uncertain: {other} departs from {reference} by {gap:.2e}"
            x, F = ref.displacement, ref.force
    except ValueError as e:  # an invalid rig: setup, not a wrong answer
        status = f"error: {e}"
    if f is not None:
        f.parent.mkdir(parents=True, exist_ok=True)
        tmp = f.with_name(f.stem + ".tmp.npz")
        np.savez(tmp, digest=digest, status=status, x=x, F=F)
        tmp.replace(f)
    return status, x, F


def run_case(sh, rig, mode: str, u: np.ndarray, dt: float, rtol: float | None = None,
             reference: str = "arkode_erk", methods: tuple = ("default", "rk4"), cache: Path | None = None,
             key: str = "") -> dict:
    """The reference and each method on one case: error, status, flags, the run's accuracy check
    (flag_measure: flagged iff > 1), time."""
    status, x_ref, F_ref = _references(sh, rig, mode, u, dt, reference, cache, key)
    if status != "ok":
        return {"reference": status}
    out: dict = {"reference": "ok"}
    for which in methods:
        try:
            if which == "rk4" and _rk4_substeps(sh, rig, mode, dt) > RK4_MAX_SUBSTEPS:
                out[which] = {"skipped": True}
                continue
            t0, c0 = time.perf_counter(), time.process_time()
            r = sh.simulate(rig, mode, u, dt=dt, options=_options(sh, which, rtol), raise_on_failure=False)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        except ValueError as e:  # refused at construction: a clear error is a status, not a wrong answer
            out[which] = {"error": math.nan, "status": f"refused: {e}", "flagged": True, "within": False,
                          "flag_measure": math.inf, "sample_flagged": True}
            continue
        if r.success:
            ex = np.max(np.abs(r.displacement - x_ref)) / max(np.max(np.abs(x_ref)), 1e-12)
            ef = np.max(np.abs(r.force - F_ref)) / max(np.max(np.abs(F_ref)), 1e-12)
            err = float(max(ex, ef))
        else:
            err = math.nan
        measure = _flag_measure(r)
        out[which] = {"error": err, "status": r.status, "flagged": not measure <= 1.0,
                      "within": bool(r.success and err <= TOLERANCE[which]), "flag_measure": measure,
                      "sample_flagged": bool(not r.success or r.work.inaccurate_samples > 0),
                      "stiff_samples": int(getattr(r.work, "stiff_samples", 0)),
                      "inaccurate_samples": int(getattr(r.work, "inaccurate_samples", 0)), "wall_s": wall,
                      "cpu_s": cpu}
    return out


def _new_counts() -> dict:
    return {"within": 0, "flagged": 0, "silent": 0, "worst_silent": 0.0, "worst": 0.0, "silent_cases": [],
            "flagged_within": 0, "sample_flagged_within": 0, "skipped": 0, "wall_s": 0.0, "cpu_s": 0.0}


def _finish_counts(c: dict) -> None:
    """Precision and recall of the run's flag as a detector of a miss (error > tolerance)."""
    tp, fn, fp = c["flagged"], c["silent"], c["flagged_within"]
    c["flag_precision"] = tp / (tp + fp) if tp + fp else None
    c["flag_recall"] = tp / (tp + fn) if tp + fn else None
    c["flag_rate_within"] = fp / c["within"] if c["within"] else None


def survey(sh, rigs: int, seed: int = 16, duration: float = 1.0, dt: float = 5e-4, progress: bool = True,
           rtol: float | None = None, family: str = "random", reference: str = "arkode_erk",
           methods: tuple = ("default", "rk4"), flag_scales: tuple = (), cache: Path | None = None) -> dict:
    """Runs `rigs` random cases of a family and counts within / flagged / silent per method, the
    flag's false alarms (flagged_within) and its precision and recall; also as if each method's
    flag bound were each of `flag_scales` times the configured one (flag_sweep)."""
    from tqdm import tqdm

    rng = np.random.default_rng(seed)
    counts = {w: _new_counts() for w in methods}
    sweep = {w: {sc: _new_counts() for sc in flag_scales} for w in methods}
    skipped, uncertain, cases = 0, 0, []
    for i in tqdm(range(rigs), disable=not progress, desc=f"{family} rigs"):
        rig, mode, u = family_case(sh, rng, duration, dt, family)
        key = f"{family}_s{seed}_d{duration:g}_dt{dt:g}_{reference}_{i}"
        res = run_case(sh, rig, mode, u, dt, rtol, reference, methods, cache, key)
        if res["reference"] != "ok":
            skipped += 1
            uncertain += res["reference"].startswith("uncertain")
            continue
        cases.append([i, mode] + [[res[w].get("error"), res[w].get("flagged"), res[w].get("stiff_samples"),
                                   res[w].get("flag_measure"), res[w].get("inaccurate_samples")] for w in methods])
        for which in methods:
            r, c = res[which], counts[which]
            if r.get("skipped"):
                c["skipped"] += 1
                continue
            c["wall_s"] += r.get("wall_s", 0.0)
            c["cpu_s"] += r.get("cpu_s", 0.0)
            if math.isfinite(r["error"]):
                c["worst"] = max(c["worst"], r["error"])
            if r["within"]:
                c["within"] += 1
                c["flagged_within"] += int(r["flagged"])
                c["sample_flagged_within"] += int(r["sample_flagged"])
            elif r["flagged"]:
                c["flagged"] += 1
            else:
                c["silent"] += 1
                c["worst_silent"] = max(c["worst_silent"], r["error"])
                c["silent_cases"].append({"index": i, "mode": mode, "error": r["error"],
                                          "stiff_samples": r["stiff_samples"]})
            for sc, s in sweep[which].items():
                flagged = not r["flag_measure"] <= sc
                s["within"] += int(r["within"])
                if r["within"]:
                    s["flagged_within"] += int(flagged)
                else:
                    s["flagged" if flagged else "silent"] += 1
    for c in list(counts.values()) + [s for w in sweep.values() for s in w.values()]:
        _finish_counts(c)
    return {"family": family, "rigs": rigs, "seed": seed, "duration_s": duration, "dt_s": dt,
            "methods": list(methods), "tolerance": TOLERANCE, "rtol": rtol, "reference": reference,
            "reference_failed": skipped,
            "reference_uncertain": uncertain, "counts": counts,
            "flag_sweep": {w: {str(sc): {k: s[k] for k in ("within", "flagged", "silent", "flagged_within",
                                                            "flag_precision", "flag_recall", "flag_rate_within")}
                               for sc, s in sweep[w].items()} for w in methods if flag_scales},
            "cases": {"columns": ["index", "mode"] + [f"{w}: [error, flagged, stiff samples, flag measure, "
                                                      "flagged samples]" for w in methods],
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
    ap.add_argument("--flag-scales", default="",
                    help="comma-separated factors: each method's flag counted as if its bound were that many "
                         "times the configured one (calibration)")
    ap.add_argument("--cache", default="", help="keep the references in this folder (reused when they match)")
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
                 flag_scales=tuple(float(v) for v in args.flag_scales.split(",") if v),
                 cache=Path(args.cache) if args.cache else None)
    print(json.dumps(res, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
