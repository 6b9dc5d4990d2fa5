"""The whole maRTHS benchmark for one record and one controller: the nominal trial and the perturbed
trials (``sh.sweep`` on a bounded process pool), ``results.json``, ``report.md`` and the plots, written
together (``atomic.FileSet``: all or nothing)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import FileSet
from ..rths.evaluation import matlab_round
from ..workers import check_workers, default_workers, process_pool
from .benchmark import (
    NOMINAL_SEED,
    benchmark_rig,
    controller_label,
    loop_config,
    make_controller,
    noise_seed,
    perturbed_plant,
    plant_label,
    rig_summary,
    run_trial,
    structures,
)
from .data import EQ_INTENSITY, FS, RECORDS, MarthsData, load_data, load_record
from .evaluation import J_COMPONENTS, J_TITLES, J_UNITS, SATURATION_LIMIT

__all__ = ["Setup", "prepare", "execute", "run_benchmark", "write_outputs", "j_table", "check_perturbed"]


def check_perturbed(value: Any, name: str = "perturbed") -> int:
    """``value`` as a whole number >= 0 (an int, or text such as ``"20"``); ValueError naming ``name`` and the
    value otherwise (``1.5``, ``"two"``, ``-1``, ``True``)."""
    if isinstance(value, bool):
        raise ValueError(f"invalid {name} = {value!r}: expected a whole number >= 0")
    if isinstance(value, str):
        text = value.strip()
        if not text.isdigit():
            raise ValueError(f"invalid {name} = {value!r}: expected a whole number >= 0")
        return int(text)
    if isinstance(value, (int, np.integer)) and value >= 0:
        return int(value)
    raise ValueError(f"invalid {name} = {value!r}: expected a whole number >= 0")


def _flat(J: dict[str, list[float]]) -> dict[str, float]:
    return {f"{j}_{c}": float(v) for j, comps in J_COMPONENTS.items() for c, v in zip(comps, J[j])}


def _perturbed_job(rig, trial: int, data: MarthsData, record, controller: str, seed: int, scale: float,
                   config: dict[str, bool]) -> dict[str, Any]:
    """One perturbed trial in a sweep worker (the rig argument of sh.sweep is unused)."""
    t = run_trial(data, record, controller, plant=perturbed_plant(seed, trial), seed=noise_seed(seed, trial),
                  scale=scale, config=loop_config(**config))
    return {**_flat(t.J), "ok": t.ok, "stable": t.stable, "failure_time": t.failure_time,
            "peak_voltage_1": t.peak_voltage[0],
            "peak_voltage_2": t.peak_voltage[1], "realizable": t.realizable, "wall_time": t.wall_time}


def _round(J: dict[str, list[float]]) -> dict[str, list[float]]:
    return {j: [matlab_round(10.0 * v) / 10.0 if math.isfinite(v) else v for v in vals] for j, vals in J.items()}


@dataclass
class Setup:
    """A validated benchmark run, before any trial (:func:`prepare`)."""
    data: MarthsData
    record: Any
    controller: Any        #: the name / "module:Class" as given, or the controller object
    built: Any             #: the nominal trial's controller object
    name: str
    description: str
    perturbed: int
    seed: int
    scale: float
    workers: int
    options: dict[str, bool]
    folder: Path
    plant: Any = None       #: the nonlinear rig (MultiActuatorRig) or None: the identified plant
    plant_name: str = "identified"
    plant_description: str = ""


def prepare(data: str | Path, record: str = "elcentro", controller: Any = "rodeac", perturbed: Any = 0,
            seed: int = NOMINAL_SEED, scale: float = EQ_INTENSITY, workers: int | None = None,
            daq_quantizer: bool = False, daq_saturation: bool = False, exact_kinematics: bool = False,
            plant: Any = "identified") -> Setup:
    """Validates every argument and input file (ValueError naming the field or the file and the value) and
    builds the nominal controller, before anything runs or is written.

    ``plant``: ``"identified"`` (the benchmark's), ``"nonlinear"`` (the calibrated two-actuator rig), a
    multi-actuator rig file or a ``MultiActuatorRig`` (:func:`benchmark_rig`); the perturbed trials draw the
    identified plant's uncertainty and exist only on it."""
    n_pert = check_perturbed(perturbed)
    rig = benchmark_rig(plant)
    if rig is not None and n_pert > 0:
        raise ValueError(f"invalid perturbed = {n_pert} with plant = {plant_label(plant)[0]!r}: the perturbed trials "
                         "draw the identified plant's uncertainty (BENCHMARK.md section 4); a nonlinear rig has none")
    if record not in RECORDS:
        raise ValueError(f"invalid record = {record!r}: expected one of {sorted(RECORDS)}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"invalid seed = {seed!r}: expected a whole number >= 0")
    if not (isinstance(scale, (int, float)) and math.isfinite(scale)):
        raise ValueError(f"invalid scale = {scale!r}: expected a finite number")
    workers = default_workers() if workers is None else check_workers(workers, "workers")
    d = load_data(data)
    rec = load_record(data, record)
    name, description = controller_label(controller)
    built = make_controller(controller, d) if isinstance(controller, str) else controller
    options = {"daq_quantizer": bool(daq_quantizer), "daq_saturation": bool(daq_saturation),
               "exact_kinematics": bool(exact_kinematics)}
    return Setup(d, rec, controller, built, name, description, n_pert, int(seed), float(scale), workers, options,
                 Path(data), rig, *plant_label(plant))


def run_benchmark(data: str | Path, record: str = "elcentro", controller: Any = "rodeac", perturbed: Any = 0,
                  seed: int = NOMINAL_SEED, scale: float = EQ_INTENSITY, workers: int | None = None,
                  progress: bool = True, daq_quantizer: bool = False, daq_saturation: bool = False,
                  exact_kinematics: bool = False, plant: Any = "identified") -> dict[str, Any]:
    """The nominal trial (noise seed ``seed``; 123 is the benchmark's) and ``perturbed`` perturbed trials
    (plants and noise seeded from ``seed`` and the trial number) of one record and controller.

    ``controller``: a built-in name, ``"module:Class"`` or a controller object (its perturbed trials then run
    here, one after another).  Everything is validated before the first run (:func:`prepare`).  Returns
    ``{"results": <the results.json content>, "trial": the nominal Trial (signals kept), "table": DataFrame of
    the perturbed trials or None}``.
    """
    return execute(prepare(data, record, controller, perturbed, seed, scale, workers, daq_quantizer, daq_saturation,
                           exact_kinematics, plant), progress)


def execute(setup: Setup, progress: bool = True) -> dict[str, Any]:
    """Runs a prepared benchmark (:func:`prepare`)."""
    s = setup
    st = structures(s.data)
    nom = run_trial(s.data, s.record, s.built, plant=s.plant, seed=s.seed, scale=s.scale,
                    config=loop_config(**s.options), structures_=st, keep_signals=True)
    runs: dict[str, Any] = {"nominal": {
        "J": nom.J, "J_rounded": _round(nom.J), "realizable": nom.realizable, "peak_voltage_V": nom.peak_voltage,
        "ok": nom.ok, "stable": nom.stable, "failure_time": nom.failure_time, "noise_seed": s.seed,
        "wall_time_s": nom.wall_time}}
    if nom.rig is not None:
        runs["nominal"]["rig"] = rig_summary(nom.rig, nom.response.channels)
    table = None
    if s.perturbed > 0:
        from ..parameter_sweep import sweep

        parallel = isinstance(s.controller, str)
        if parallel:
            executor = process_pool(min(s.workers, s.perturbed), "workers")
        else:  # a controller object cannot go to worker processes: its trials run here, one after another
            from concurrent.futures import ThreadPoolExecutor
            executor = ThreadPoolExecutor(max_workers=1)
        try:
            ctrl = s.controller if parallel else s.built
            table = sweep(grid={"trial": list(range(1, s.perturbed + 1))}, run=_perturbed_job,
                          fixed={"data": s.data, "record": s.record, "controller": ctrl, "seed": s.seed,
                                 "scale": s.scale, "config": s.options},
                          executor=executor, progress=progress)
        finally:
            executor.shutdown(wait=True)
        table = table.drop(columns=["data", "record", "controller", "config"])
        if "error" in table.columns and table["error"].notna().any():
            raise RuntimeError(f"perturbed trial failed: {table['error'].dropna().iloc[0]}")
        runs["perturbed"] = _statistics(table, s.perturbed)
    meta = {"benchmark": "virtual multi-axial RTHS (maRTHS), Condori Uribe et al. 2023; RoDeAC: Quiroz et al. 2024",
            "data": str(s.folder), "record": s.record.name, "record_source": s.record.source,
            "eq_intensity": s.scale, "fs_Hz": FS, "samples": int(s.record.samples(FS)), "controller": s.name,
            "controller_description": s.description, "seed": s.seed,
            "noise": "Simulink Random Number block algorithm, one sequence on both channels",
            "plant": s.plant_name, "plant_description": s.plant_description,
            "perturbed_runs": s.perturbed, **s.options, "saturation_limit_V": SATURATION_LIMIT,
            "J_components": {j: list(c) for j, c in J_COMPONENTS.items()}, "J_units": J_UNITS, "J_titles": J_TITLES}
    return {"results": {"meta": meta, "runs": runs}, "trial": nom, "table": table}


def _statistics(table, n: int) -> dict[str, Any]:
    def per_j(fn) -> dict[str, list[float]]:
        return {j: [float(fn(table[f"{j}_{c}"].to_numpy(dtype=float))) for c in comps]
                for j, comps in J_COMPONENTS.items()}

    mean = per_j(np.mean)
    real = [bool(v) for v in table["realizable"]]
    return {"runs": n,
            "J_mean": mean, "J_mean_rounded": _round(mean),
            "J_std": per_j(lambda v: np.std(v, ddof=1) if v.size > 1 else 0.0),
            "J_min": per_j(np.min), "J_max": per_j(np.max),
            "ran_to_end": int(table["ok"].sum()), "stable": int(table["stable"].sum()),
            # S5: only the last trial decides the final message, as coded; all trials are listed too
            "realizable": real[-1], "realizable_all": all(real),
            "not_realizable_trials": [int(t) for t, ok in zip(table["trial"], real) if not ok],
            "peak_voltage_V": [[float(a), float(b)] for a, b in zip(table["peak_voltage_1"], table["peak_voltage_2"])],
            "trials": [{"trial": int(r["trial"]), "J": {j: [float(r[f"{j}_{c}"]) for c in comps]
                                                       for j, comps in J_COMPONENTS.items()},
                        "ok": bool(r["ok"]), "realizable": bool(r["realizable"])} for _, r in table.iterrows()]}


# ----------------------------------------------------------------------------- outputs

def _fmt(v: float, nd: int = 4) -> str:
    return "nan" if not math.isfinite(v) else f"{v:.{nd}f}"


def j_table(results: dict[str, Any]) -> str:
    """The criteria by name (markdown): one row per component, the nominal value and (if run) the perturbed
    mean +- std."""
    runs = results["runs"]
    pert = runs.get("perturbed")
    head = "| J | criterion | component | nominal | unit |" + (" perturbed mean ± std |" if pert else "") + "\n"
    head += "|---|---|---|---:|---|" + ("---:|" if pert else "") + "\n"
    rows = []
    for j, comps in J_COMPONENTS.items():
        for i, c in enumerate(comps):
            row = f"| {j} | {J_TITLES[j]} | {c} | {_fmt(runs['nominal']['J'][j][i])} | {J_UNITS[j]} |"
            if pert:
                row += f" {_fmt(pert['J_mean'][j][i])} ± {_fmt(pert['J_std'][j][i])} |"
            rows.append(row)
    return head + "\n".join(rows) + "\n"


def _window(t: np.ndarray, signal: np.ndarray, half: float = 2.0) -> np.ndarray:
    k = int(np.argmax(np.abs(signal)))
    return (t > t[k] - half) & (t < t[k] + half)


def _plots(trial, out: Path, files: FileSet) -> list[str]:
    from matplotlib.figure import Figure

    s = trial.response.channels
    t = s["time"]
    names = []
    # tracking in translation and rotation: the numerical substructure's interface, the estimate, the reference
    fig = Figure(figsize=(10, 6))
    for row, (q, unit, scale) in enumerate((("x", "mm", 1e3), ("theta", "mrad", 1e3))):
        w = _window(t, s[f"{q}_numerical"])
        for col, sel in enumerate((slice(None), w)):
            ax = fig.add_subplot(2, 2, 2 * row + col + 1)
            ax.plot(t[sel], scale * s[f"{q}_numerical"][sel], label="numerical (target)", lw=0.9)
            ax.plot(t[sel], scale * s[f"{q}_estimate"][sel], label="estimated from the actuators", lw=0.8)
            ax.plot(t[sel], scale * s[f"{q}_reference"][sel], "--", label="reference", lw=0.8)
            ax.set_ylabel(f"{'translation' if q == 'x' else 'rotation'} [{unit}]")
            if row == 1:
                ax.set_xlabel("time [s]")
            if row == 0 and col == 0:
                ax.legend(fontsize=7, loc="upper right")
    fig.suptitle("Tracking of the interface node (left: whole record; right: 4 s around the peak)", fontsize=9)
    fig.tight_layout()
    fig.savefig(files.path(out / "tracking.png"), dpi=110)
    names.append("tracking.png")
    # tracking error of each actuator
    fig = Figure(figsize=(10, 4))
    ax = fig.add_subplot(1, 1, 1)
    for i in (1, 2):
        ax.plot(t, 1e3 * (s[f"measured_{i}"] - s[f"target_{i}"]), lw=0.6, label=f"actuator {i}: measured - target")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tracking error [mm]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(files.path(out / "tracking_error.png"), dpi=110)
    names.append("tracking_error.png")
    # synchronisation between the two actuators: the stroke difference (the rotation) and the error difference
    fig = Figure(figsize=(10, 5))
    d_t = s["target_1"] - s["target_2"]
    d_m = s["measured_1"] - s["measured_2"]
    w = _window(t, d_t)
    ax = fig.add_subplot(2, 1, 1)
    ax.plot(t[w], 1e3 * d_t[w], label="target: xa1 - xa2")
    ax.plot(t[w], 1e3 * d_m[w], lw=0.8, label="measured: xa1 - xa2")
    ax.set_ylabel("stroke difference [mm]")
    ax.legend(fontsize=7)
    ax = fig.add_subplot(2, 1, 2)
    ax.plot(t, 1e3 * (d_m - d_t), lw=0.6)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("synchronisation error [mm]")
    fig.tight_layout()
    fig.savefig(files.path(out / "synchronisation.png"), dpi=110)
    names.append("synchronisation.png")
    if trial.rig is not None:
        fig = Figure(figsize=(10, 6))
        rig_figure(fig, trial.rig)
        fig.savefig(files.path(out / "rig.png"), dpi=110)
        names.append("rig.png")
    return names


def rig_figure(fig, res, label: str = "") -> None:
    """Draws the nonlinear rig's channels of a run into ``fig``: each actuator's spool opening against its limit,
    the two load-cell forces and their difference [kN], and the opposing force [kN]."""
    t = res.time
    ax = fig.add_subplot(3, 1, 1)
    for i in range(1, res.actuators + 1):
        ax.plot(t, res[f"actuator{i}.spool"], lw=0.6, label=f"actuator {i}")
    lim = max(float(r.x_v_max) for r in res.multi_rig.rigs)
    ax.axhline(lim, color="k", ls=":", lw=0.8)
    ax.axhline(-lim, color="k", ls=":", lw=0.8)
    ax.set_ylabel("spool opening [-]")
    ax.legend(fontsize=7, loc="upper right")
    ax = fig.add_subplot(3, 1, 2)
    for i in (1, 2):
        ax.plot(t, 1e-3 * res[f"actuator{i}.force"], lw=0.6, label=f"F{i} (load cell)")
    ax.plot(t, 1e-3 * (res["actuator1.force"] - res["actuator2.force"]), lw=0.6, label="F1 - F2")
    ax.set_ylabel("force [kN]")
    ax.legend(fontsize=7, loc="upper right")
    ax = fig.add_subplot(3, 1, 3)
    ax.plot(t, 1e-3 * res["node.opposing_force"], lw=0.6)
    ax.set_ylabel("opposing force [kN]")
    ax.set_xlabel("time [s]")
    fig.suptitle(f"Nonlinear rig{': ' + label if label else ''}: valve spools, actuator forces, force fighting",
                 fontsize=9)
    fig.tight_layout()


def write_outputs(run: dict[str, Any], out: str | Path) -> Path:
    """results.json, report.md, tracking.png, tracking_error.png and synchronisation.png in ``out``, renamed
    into place together once all are written (atomic.FileSet)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with FileSet() as files:
        res = run["results"]
        files.write_text(out / "results.json", json.dumps(res, indent=2, allow_nan=True))
        plots = _plots(run["trial"], out, files) if run["trial"].response is not None else []
        files.write_text(out / "report.md", _report(res, plots))
    return out


def _report(res: dict[str, Any], plots: list[str]) -> str:
    meta, runs = res["meta"], res["runs"]
    nom = runs["nominal"]
    lines = [f"# Multi-axial RTHS benchmark (maRTHS): {meta['record']} × {meta['eq_intensity']}, "
             f"controller {meta['controller']}", "",
             f"- controller: {meta['controller']}: {meta['controller_description']}",
             f"- plant: {meta['plant']}: {meta['plant_description']}",
             f"- record: {meta['record_source']} ({meta['samples']} samples at {meta['fs_Hz']} Hz)",
             f"- sensor noise: {meta['noise']}, seed {meta['seed']} on the nominal trial"
             + (" (the benchmark's)" if meta["seed"] == NOMINAL_SEED else ""),
             f"- DAQ blocks: quantiser {'on' if meta['daq_quantizer'] else 'off'}, saturation "
             f"{'on' if meta['daq_saturation'] else 'off'} (the model has neither); kinematics: "
             f"{'exact inverse' if meta['exact_kinematics'] else 'the model estimate'}",
             f"- perturbed trials: {meta['perturbed_runs']}", "",
             "J1, J4 in ms, the others in % (BENCHMARK.md section 8), unrounded; S5 prints them rounded to 0.1.", "",
             j_table(res), ""]
    if not nom["ok"]:
        lines += [f"**The nominal trial failed at t = {nom['failure_time']:.4f} s.**", ""]
    elif not nom["stable"]:
        lines += ["**The nominal trial is not stable: a tracking error (J2) is 100 % of its target or more.**", ""]
    v1, v2 = nom["peak_voltage_V"]
    lines += [f"Peak command voltages (nominal): {v1:.3f} V, {v2:.3f} V; the controller is "
              f"{'realizable' if nom['realizable'] else 'NOT realizable'} (not realizable when both exceed "
              f"{meta['saturation_limit_V']} V)."]
    if "perturbed" in runs:
        p = runs["perturbed"]
        lines += [f"Perturbed trials: {p['ran_to_end']} of {p['runs']} ran to the end, {p['stable']} stable "
                  "(J2 < 100 %); realizable as S5 decides "
                  f"(the last trial): {'yes' if p['realizable'] else 'no'}; trials not realizable: "
                  f"{p['not_realizable_trials'] or 'none'}."]
    if "rig" in nom:
        lines += ["", _rig_lines(nom["rig"])]
    lines += [""] + [f"![{Path(n).stem}]({n})" for n in plots] + [""]
    return "\n".join(lines)


def _rig_lines(rig: dict[str, Any]) -> str:
    """The nonlinear rig's peaks (report.md)."""
    rows = ["What the nonlinear rig shows (the loop's commands replayed on the rig: identical strokes, largest "
            f"difference {rig['replay_stroke_difference_m']:.3g} m):", "",
            "| actuator | peak force [kN] | peak spool [-] (limit) | spool > 90 % of limit [% of samples] | "
            "peak drive [V] | peak friction [N] |", "|---|---:|---:|---:|---:|---:|"]
    for i, a in enumerate(rig["actuators"], start=1):
        rows.append(f"| {i} | {a['peak_force_N'] / 1e3:.2f} | {a['peak_spool']:.3f} ({a['spool_limit']:g}) | "
                    f"{100 * a['spool_above_90pct_share']:.2f} | {a['peak_drive_V']:.3f} | "
                    f"{a['peak_friction_N']:.1f} |")
    rows += ["", f"Force difference F1 - F2: peak {rig['peak_force_difference_N'] / 1e3:.2f} kN, rms "
             f"{rig['rms_force_difference_N'] / 1e3:.2f} kN; peak opposing force (cancelling in the x resultant) "
             f"{rig['peak_opposing_force_N'] / 1e3:.2f} kN.",
             "Rig warnings: " + ("; ".join(rig["warnings"]) if rig["warnings"] else "none") + "."]
    return "\n".join(rows)

