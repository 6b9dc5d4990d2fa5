"""The same compensator on the maRTHS benchmark's identified linear plant and on our nonlinear two-actuator rig.

Issue 23, item 5: the virtual multi-axial RTHS benchmark (BENCHMARK.md: the 29-DOF reference and numerical
substructure, the physical frame's feedback force, the sensors and noise) run with RoDeAC (and, for contrast,
its fixed FIR ``rodeac_fixed`` and no compensation ``none``) behind five plants:

* ``identified``: the benchmark's identified 2 x 2 transfer matrix (plantFRAME_SS), linear;
* ``rig-linear``: the calibrated two-actuator rig (``sh.marths_rig()``, docs/multi-actuator.md) with its
  nonlinear effects off (load pressure, flow curve, friction, spool and drive saturation): its own linear
  plant, fitted to the identified one over 0-50 Hz.  Identified vs rig-linear is the calibration's mismatch;
* ``rig``: the calibrated rig, every effect on (Zhao et al. 2003's actuator: the valve flow's load-pressure
  root, the flow curve, compressibility, leakage, piston friction F_c = 31.6 N, saturations);
* ``rig-small-valve``: actuator 2's servovalve ``VALVE_FACTOR`` times smaller (K_v / k) and its proportional
  gain k times larger (G_p k): the same small-signal loop gain, hence the same linearisation and the same
  identified plant, but its spool must open k times wider for the same flow and meets its stops;
* ``rig-friction``: seal friction F_c = ``FRICTION_N`` on both pistons (the calibrated rig has the paper's
  31.6 N, 0.02 % of the forces this frame asks of the actuators).

Rig versus rig-linear is what the nonlinearity does; the two variants are what the identified plant cannot
show at all.  For each run: J1-J10 (BENCHMARK.md section 8), and on the rigs the channels only a physical
model has (the loop's commands replayed on the rig: identical strokes): each actuator's spool against its
limit, the load-cell forces, their difference F1 - F2 and the opposing force (the force that cancels in the x
resultant: the actuators pushing against each other through the frame's rotational stiffness).

    python studies/marths_linear_vs_nonlinear.py --out OUT [--data ../shared/marths-data]
        [--records elcentro,kobe,morgan] [--controllers rodeac,rodeac_fixed,none] [--write]

writes ``OUT/results.json`` (every J component unrounded, the rig's peaks, per run), ``OUT/signals.npz`` (what the
figures plot), ``OUT/table.md`` and ``OUT/linear_vs_nonlinear_<record>.png`` (``--replot``: these two again from
the first two, without running); ``--write`` also puts the El Centro figure in docs/figures and the
tables in docs/multi-actuator.md (between ``<!-- marths_linear_vs_nonlinear -->`` markers).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics import marths
from servohydraulics.atomic import FileSet, replace_marked, write_with
from servohydraulics.multi_rig import MultiActuatorRig

ROOT = Path(__file__).resolve().parents[1]
#: Actuator 2's valve is this many times smaller in rig-small-valve (its G_p as many times larger): on the
#: calibrated rig its spool opens to 0.042 at El Centro's peak (actuator 1's to 0.018), so 30 times that asks
#: for 1.25 of a spool whose stops are at 1.
VALVE_FACTOR = 30.0
SMALL_VALVE_ACTUATOR = 1  # 0-based: actuator 2
#: Coulomb (seal) friction on each piston in rig-friction [N].
FRICTION_N = 2000.0
PLANTS = ("identified", "rig-linear", "rig", "rig-small-valve", "rig-friction")
CONTROLLERS = ("rodeac", "rodeac_fixed", "none")
LINEAR_OFF = ("load_pressure", "flow_nonlinearity", "coulomb_friction", "spool_saturation", "drive_saturation",
              "lugre_friction")


def _variant(base: MultiActuatorRig, change) -> MultiActuatorRig:
    rigs = [sh.copy_rig(r) for r in base.rigs]
    for i, r in enumerate(rigs):
        change(i, r)
    out = MultiActuatorRig(rigs, base.arms, base.angles, base.specimen)
    out.frame = base.frame
    return out


def plants() -> dict[str, MultiActuatorRig | None]:
    """The five plants (None: the identified plant)."""
    base = sh.marths_rig()

    def linear(i, r):
        for name in LINEAR_OFF:
            setattr(r.effects, name, False)

    def small_valve(i, r):
        if i == SMALL_VALVE_ACTUATOR:
            r.K_v /= VALVE_FACTOR
            r.G_p *= VALVE_FACTOR

    def friction(i, r):
        r.F_c = FRICTION_N
        r.effects.coulomb_friction = True

    return {"identified": None, "rig-linear": _variant(base, linear), "rig": base,
            "rig-small-valve": _variant(base, small_valve), "rig-friction": _variant(base, friction)}


_CACHE: dict = {}
#: The signals a figure needs, per run: the loop's (maRTHS channels) and the rig's.
LOOP_KEEP = ("time", "x_numerical", "x_estimate", "theta_numerical", "theta_estimate", "measured_1", "target_1",
             "measured_2", "target_2")
RIG_KEEP = ("actuator1.spool", "actuator2.spool", "actuator1.force", "actuator2.force", "actuator1.friction",
            "actuator1.velocity", "actuator2.friction", "node.opposing_force")


def one_run(data_dir: Path, record: str, plant: str, controller: str, keep: bool) -> tuple[dict, dict | None]:
    """One (record, plant, controller) in a worker process: its results entry and (``keep``) the signals."""
    if data_dir not in _CACHE:
        data = marths.load_data(data_dir)
        _CACHE[data_dir] = (data, marths.structures(data), plants())
    data, st, ps = _CACHE[data_dir]
    rec = marths.load_record(data_dir, record)
    t0 = time.perf_counter()
    trial = marths.run_trial(data, rec, controller, plant=ps[plant], structures_=st, keep_signals=True)
    entry = {"J": trial.J, "ok": trial.ok, "stable": trial.stable, "failure_time": trial.failure_time,
             "peak_voltage_V": trial.peak_voltage, "loop_wall_time_s": trial.wall_time,
             "wall_time_s": time.perf_counter() - t0, "internal_steps": int(trial.work.internal_steps)}
    if trial.rig is not None:
        entry["rig"] = marths.rig_summary(trial.rig, trial.response.channels)
    signals = None
    if keep:
        signals = {k: np.asarray(trial.response.channels[k]) for k in LOOP_KEEP}
        if trial.rig is not None:
            signals.update({k: np.asarray(trial.rig[k]) for k in RIG_KEEP})
            signals["rig.time"] = np.asarray(trial.rig.time)
    return entry, signals


def run_all(data_dir: Path, records: list[str], controllers: list[str], workers: int = 2) -> tuple[dict, dict]:
    """Every (record, plant, controller) on ``workers`` processes: results (JSON-able) and the signals of the
    first controller's runs (for the figures)."""
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from tqdm import tqdm

    results: dict = {}
    kept: dict = {}
    # the slow runs (the rigs, the adaptive controller) first, so that the two processes end together
    jobs = [(r, p, c) for r in records for c in controllers for p in reversed(PLANTS)]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        futs = {pool.submit(one_run, data_dir, r, p, c, c == controllers[0]): (r, p, c) for r, p, c in jobs}
        for fut in tqdm(as_completed(futs), total=len(futs), desc="runs"):
            r, p, c = futs[fut]
            entry, signals = fut.result()
            results.setdefault(r, {}).setdefault(p, {})[c] = entry
            if signals is not None:
                kept[(r, p)] = signals
    # in the order of PLANTS and the controllers
    results = {r: {p: {c: results[r][p][c] for c in controllers} for p in PLANTS} for r in records}
    return results, kept


def _f(v: float, nd: int = 2) -> str:
    return "nan" if not math.isfinite(v) else f"{v:.{nd}f}"


def j_table(results: dict, record: str, controller: str) -> str:
    """Every J component (rows) for each plant (columns), one record and controller."""
    plist = [p for p in PLANTS if p in results[record]]
    head = "| J | component | unit | " + " | ".join(plist) + " |\n|---|---|---|" + "---:|" * len(plist) + "\n"
    rows = []
    for j, comps in marths.J_COMPONENTS.items():
        for i, c in enumerate(comps):
            vals = [_f(results[record][p][controller]["J"][j][i]) for p in plist]
            rows.append(f"| {j} | {c} | {marths.J_UNITS[j]} | " + " | ".join(vals) + " |")
    return head + "\n".join(rows) + "\n"


def summary_table(results: dict, record: str) -> str:
    """Per plant and controller: the main J and the rig's peaks."""
    head = ("| plant | controller | J2 act1 / act2 [%] | J3 act1 / act2 [%] | J5 x / θ [%] | J7 x / θ [%] | "
            "J9 x / θ [%] | peak spool act1 / act2 [-] | peak F1 - F2 [kN] | peak opposing force [kN] |\n"
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n")
    rows = []
    for p in PLANTS:
        if p not in results[record]:
            continue
        for c, e in results[record][p].items():
            J = e["J"]
            pair = {j: f"{_f(J[j][0])} / {_f(J[j][1])}" for j in ("J2", "J3", "J5", "J7", "J9")}
            rig = e.get("rig")
            if rig:
                a = rig["actuators"]
                extra = (f"{a[0]['peak_spool']:.3f} / {a[1]['peak_spool']:.3f} | "
                         f"{rig['peak_force_difference_N'] / 1e3:.1f} | {rig['peak_opposing_force_N'] / 1e3:.1f}")
            else:
                extra = "- | - | -"
            flag = "" if e["stable"] else " (not stable)"
            rows.append(f"| {p} | {c}{flag} | {pair['J2']} | {pair['J3']} | {pair['J5']} | {pair['J7']} | "
                        f"{pair['J9']} | {extra} |")
    return head + "\n".join(rows) + "\n"


def _window(t: np.ndarray, s: np.ndarray, half: float = 1.5) -> np.ndarray:
    k = int(np.argmax(np.abs(s)))
    return (t > t[k] - half) & (t < t[k] + half)


def figure(kept: dict, record: str, controller: str):
    """Tracking and errors in x and θ, per-actuator tracking error, the spools and the force fighting."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 10))
    base = kept[(record, "identified")]
    t = base["time"]
    w = _window(t, base["x_numerical"])
    styles = {"identified": ("k", "-"), "rig-linear": ("tab:gray", ":"), "rig": ("tab:blue", "-"),
              "rig-small-valve": ("tab:red", "-"), "rig-friction": ("tab:green", "-")}
    shown = [p for p in ("identified", "rig", "rig-small-valve", "rig-friction") if (record, p) in kept]
    for col, (q, unit) in enumerate((("x", "mm"), ("theta", "mrad"))):
        ax = fig.add_subplot(4, 2, 1 + col)
        ax.plot(t[w], 1e3 * base[f"{q}_numerical"][w], color="0.6", lw=2.0, label="target (numerical, identified)")
        for p in shown:
            s = kept[(record, p)]
            ax.plot(t[w], 1e3 * s[f"{q}_estimate"][w], color=styles[p][0], ls=styles[p][1], lw=0.8, label=p)
        ax.set_ylabel(f"{'x' if q == 'x' else 'θ'} measured [{unit}]")
        ax.legend(fontsize=6, loc="upper right")
        ax = fig.add_subplot(4, 2, 3 + col)
        for p in reversed(shown):  # the identified plant's on top
            s = kept[(record, p)]
            ax.plot(t, 1e3 * (s[f"{q}_estimate"] - s[f"{q}_numerical"]), color=styles[p][0], ls=styles[p][1],
                    lw=0.5, label=p)
        ax.set_ylabel(f"{'x' if q == 'x' else 'θ'} error vs numerical [{unit}]")
        ax.set_xlabel("time [s] (whole record)")
    for col, act in enumerate((1, 2)):
        ax = fig.add_subplot(4, 2, 5 + col)
        for p in ("rig-small-valve", "rig"):
            if "rig.time" in kept.get((record, p), {}):
                r = kept[(record, p)]
                ax.plot(r["rig.time"], r[f"actuator{act}.spool"], color=styles[p][0], lw=0.5, label=p)
        ax.axhline(1.0, color="k", ls=":", lw=0.8)
        ax.axhline(-1.0, color="k", ls=":", lw=0.8)
        ax.set_ylabel(f"actuator {act} spool [-]")
        ax.legend(fontsize=6, loc="lower right")
    ax = fig.add_subplot(4, 2, 7)
    for p in ("rig-small-valve", "rig-friction", "rig"):
        if "rig.time" in kept.get((record, p), {}):
            r = kept[(record, p)]
            ax.plot(r["rig.time"], 1e-3 * (r["actuator1.force"] - r["actuator2.force"]), color=styles[p][0], lw=0.5,
                    label=p)
    ax.set_ylabel("F1 - F2 [kN]")
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=6, loc="lower right")
    ax = fig.add_subplot(4, 2, 8)
    for p in ("rig-friction", "rig"):
        if "rig.time" in kept.get((record, p), {}):
            r = kept[(record, p)]
            ww = _window(r["rig.time"], base["x_numerical"], 1.0)
            ax.plot(r["rig.time"][ww], 1e-3 * r["actuator1.friction"][ww], color=styles[p][0], lw=0.8,
                    label=f"{p}: friction")
            ax.plot(r["rig.time"][ww], 1e-3 * r["actuator1.force"][ww] / 10, color=styles[p][0], lw=0.5, ls="--",
                    label=f"{p}: load cell / 10")
    ax.set_ylabel("actuator 1 [kN]")
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=6, loc="lower right")
    fig.suptitle(f"maRTHS, {record} × {marths.EQ_INTENSITY}, {controller}: the identified linear plant against the "
                 "nonlinear two-actuator rig (row 1: 3 s around the peak)", fontsize=9)
    fig.tight_layout()
    return fig


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "marths-data")
    ap.add_argument("--records", default="elcentro", help="comma-separated: elcentro, kobe, morgan")
    ap.add_argument("--controllers", default=",".join(CONTROLLERS), help="comma-separated; the first is plotted")
    ap.add_argument("--out", type=Path, required=True, help="output folder")
    ap.add_argument("--write", action="store_true", help="also the docs figure and the tables in the docs")
    ap.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    ap.add_argument("--replot", action="store_true",
                    help="no runs: the tables and figures from OUT/results.json and OUT/signals.npz of an earlier run")
    args = ap.parse_args()
    records = [r.strip() for r in args.records.split(",") if r.strip()]
    controllers = [c.strip() for c in args.controllers.split(",") if c.strip()]
    for r in records:
        if r not in marths.RECORDS:
            raise SystemExit(f"error: invalid --records entry = {r!r}: expected one of {sorted(marths.RECORDS)}")
    for c in controllers:
        if c not in marths.CONTROLLERS:
            raise SystemExit(f"error: invalid --controllers entry = {c!r}: expected one of "
                             f"{sorted(marths.CONTROLLERS)}")
    args.out.mkdir(parents=True, exist_ok=True)
    if args.replot:  # the tables and figures again from a run's results.json and signals.npz
        saved = json.loads((args.out / "results.json").read_text())
        results, wall, workers = saved["results"], saved["wall_time_s"], saved["workers"]
        with np.load(args.out / "signals.npz") as z:
            kept: dict = {}
            for key in z.files:
                r, p, k = key.split("|")
                kept.setdefault((r, p), {})[k] = z[key]
        records = list(results)
        controllers = list(results[records[0]][PLANTS[0]])
    else:
        t0 = time.perf_counter()
        results, kept = run_all(args.data, records, controllers, args.workers)
        wall, workers = time.perf_counter() - t0, args.workers
        with FileSet() as files:  # the runs first: a figure can be redone with --replot
            files.write_text(args.out / "results.json", json.dumps(
                {"valve_factor": VALVE_FACTOR, "small_valve_actuator": SMALL_VALVE_ACTUATOR + 1,
                 "friction_N": FRICTION_N, "wall_time_s": wall, "workers": workers, "results": results},
                indent=2, allow_nan=True))
            with open(files.path(args.out / "signals.npz"), "wb") as fh:
                np.savez_compressed(fh, **{f"{r}|{p}|{k}": v for (r, p), sig in kept.items() for k, v in sig.items()})
    text = [f"Valve factor {VALVE_FACTOR:g} on actuator {SMALL_VALVE_ACTUATOR + 1} (rig-small-valve), seal friction "
            f"{FRICTION_N:g} N (rig-friction); noise seed 123; J in % (J1, J4 in ms), shown to 2 decimals "
            f"(OUT/results.json: unrounded). {len(records) * len(PLANTS) * len(controllers)} runs in {wall:.0f} s on "
            f"{workers} processes.", ""]
    for r in records:
        text += [f"**{r} × {marths.EQ_INTENSITY}, {controllers[0]}: every J component**", "",
                 j_table(results, r, controllers[0]), f"**{r}: all controllers, with the rig's peaks**", "",
                 summary_table(results, r)]
    table = "\n".join(text)
    print(table)
    with FileSet() as files:
        files.write_text(args.out / "table.md", table)
        for r in records:
            figure(kept, r, controllers[0]).savefig(files.path(args.out / f"linear_vs_nonlinear_{r}.png"), dpi=110)
    if args.write:
        r = records[0]
        write_with(ROOT / "docs" / "figures" / "marths_linear_vs_nonlinear.png",
                   lambda p: figure(kept, r, controllers[0]).savefig(p, dpi=100, format="png"))
        replace_marked(ROOT / "docs" / "multi-actuator.md", "marths_linear_vs_nonlinear", table)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
