"""The whole benchmark for a set of cases: results.json, a markdown report
with the J table, tracking, synchronisation and criteria plots (``rths.figures``:
matplotlib Figures saved to files)."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..atomic import FileSet
from ..workers import check_workers, default_workers, process_pool
from .benchmark import FORCE_LIMIT, controller_label, noise_generator, run_case
from .data import EQ_INTENSITY, embedded_case, load_case, load_record, synthetic_record
from .evaluation import J_LABELS, J_NAMES

__all__ = ["run_benchmark", "write_outputs", "j_table"]

SYNTHETIC_LABEL = ("EMBEDDED DEFAULT: reference structure rebuilt from the published parameters, driven by a "
                   "SYNTHETIC ground motion. These are NOT the benchmark's records or results.")


def parse_cases(text: str | Sequence[int]) -> list[int]:
    if isinstance(text, str):
        try:
            cases = [int(v) for v in text.split(",") if v.strip()]
        except ValueError:
            raise ValueError(f"invalid cases = {text!r}: expected a comma-separated list of 1, 2, 3, 4") from None
    else:
        cases = [int(v) for v in text]
    if not cases or any(c not in (1, 2, 3, 4) for c in cases):
        raise ValueError(f"invalid cases = {text!r}: expected a comma-separated list of 1, 2, 3, 4")
    return cases


def run_benchmark(data: str | Path | None = None, record: str = "elcentro", cases: str | Sequence[int] = "1,2,3,4",
                  controller: Any = "sample", perturbed: int = 0, seed: int = 0, scale: float = EQ_INTENSITY,
                  workers: int | None = None, progress: bool = True, csi: str = "exact",
                  noise: str = "simulink") -> dict[str, Any]:
    """Runs the benchmark: per case the nominal trial (signals kept) and
    ``perturbed`` perturbed trials (through ``sh.sweep`` on one process pool).

    ``controller``: a built-in name, ``"module:Class"`` (imported from PYTHONPATH, built with
    no arguments) or a controller object (``rths.run_case``).
    ``csi``: ``"exact"`` (a2 x', the spec's default) or ``"derivative-block"`` (the code's
    Simulink Derivative block, BENCHMARK.md 2.1).
    ``noise``: ``"simulink"`` (the official SENSORS subsystem's generator; seed 0 is the
    official run's realisation) or ``"mersenne"``.
    Without ``data``: the embedded default (published parameters, synthetic
    ground motion), labelled as not the benchmark's.
    Returns ``{"results": <results.json content>, "trials": {case: Trial}, "tables": {case: DataFrame}}``.
    """
    case_list = parse_cases(cases)
    noise_generator(noise)
    if csi not in ("exact", "derivative-block"):
        raise ValueError(f"invalid csi = {csi!r}: expected 'exact' or 'derivative-block'")
    controller_name, controller_description = controller_label(controller)  # a bad spec: ValueError here
    if isinstance(perturbed, bool) or int(perturbed) != perturbed or perturbed < 0:
        raise ValueError(f"invalid perturbed = {perturbed!r}: expected an integer >= 0")
    if data is None:
        rec = load_record(None, "chirp") if record == "chirp" else synthetic_record()
        load = embedded_case
    else:
        rec = load_record(data, record)
        load = lambda n: load_case(data, n)  # noqa: E731
    results: dict[str, Any] = {"cases": {}}
    meta = {"record": rec.name, "record_source": rec.source, "synthetic": rec.synthetic,
            "controller": controller_name, "controller_description": controller_description,
            "eq_intensity": scale, "seed": seed, "perturbed_runs": int(perturbed), "fs_Hz": 4096,
            "J_names": list(J_NAMES), "J_labels": list(J_LABELS), "force_limit_N": FORCE_LIMIT, "csi": csi,
            "noise": noise}
    if rec.synthetic:
        meta["label"] = SYNTHETIC_LABEL
    elif data is None:
        meta["label"] = ("EMBEDDED DEFAULT: reference structure rebuilt from the published parameters, driven by the "
                         "benchmark's chirp (no published results).")
    loaded = {n: load(n) for n in case_list}  # every case validated before the first run
    trials, tables = {}, {}
    # a controller object cannot go to worker processes: run_case then runs its trials here, one after another
    parallel = perturbed > 0 and isinstance(controller, str)
    workers = default_workers() if workers is None else check_workers(workers)
    executor = process_pool(workers) if parallel else None
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(case_list) * (1 + int(perturbed)), desc="rths-benchmark", unit="run")
    try:
        for n in case_list:
            case = loaded[n]
            out = run_case(case, rec, controller, perturbed=int(perturbed), seed=seed, scale=scale,
                           executor=executor, progress=False, keep_signals=True,
                           csi_derivative_block=csi == "derivative-block", noise=noise)
            nom = out["nominal"]
            entry: dict[str, Any] = {"nominal": {"J": nom["J"], "criteria": nom["criteria"],
                                                 "max_force_N": nom["max_force_N"],
                                                 "max_displacement_m": nom["max_displacement_m"],
                                                 "PSI": nom["PSI"]}}
            if perturbed > 0:
                p = out["perturbed"]
                entry["perturbed"] = {"J_mean": p["J_mean"], "J_std": p["J_std"], "criteria_mean": p["criteria_mean"],
                                      "criteria_std": p["criteria_std"], "runs": p["runs"]}
                meta.setdefault("perturbed_stable", {})[str(n)] = p["stable"]
                meta.setdefault("perturbed_ran_to_end", {})[str(n)] = p["ran_to_end"]
                meta.setdefault("perturbed_capacity_exceeded", {})[str(n)] = p["capacity_exceeded"]
                tables[n] = out["table"]
            meta.setdefault("case_source", {})[str(n)] = case.source
            meta.setdefault("max_velocity_m_per_s", {})[str(n)] = nom["max_velocity_m_per_s"]
            results["cases"][str(n)] = entry
            trials[n] = out["trial"]
            if bar is not None:
                bar.update(1 + int(perturbed))
    finally:
        if bar is not None:
            bar.close()
        if executor is not None:
            executor.shutdown(wait=True)
    results["meta"] = meta
    return {"results": results, "trials": trials, "tables": tables}


def _fmt(v: float, nd: int = 2) -> str:
    return "nan" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{nd}f}"


def j_table(results: dict[str, Any]) -> str:
    """The J table (markdown): one row per case, nominal and (if run) perturbed mean +- std;
    the columns are the criteria's names (``J1_delay_ms``, ...)."""
    head = "| Case | Trial | " + " | ".join(J_NAMES) + " | max f [kN] | PSI |\n"
    head += "|" + " --- |" * 13 + "\n"
    rows = []
    for n, e in results["cases"].items():
        nom = e["nominal"]
        rows.append(f"| {n} | nominal | " + " | ".join(_fmt(v) for v in nom["J"])
                    + f" | {nom['max_force_N'] / 1e3:.2f} | {nom['PSI']:.3f} |")
        if "perturbed" in e:
            p = e["perturbed"]
            rows.append(f"| {n} | perturbed ({p['runs']}) | "
                        + " | ".join(f"{_fmt(m)} ± {_fmt(s)}" for m, s in zip(p["J_mean"], p["J_std"])) + " | | |")
    return head + "\n".join(rows) + "\n"


def _plots(run: dict[str, Any], out: Path, files_out: FileSet) -> list[str]:
    """tracking.png, synchronization.png and criteria.png (``rths.figures``) into ``out``."""
    from .figures import criteria_figure, synchronization_figure, tracking_figure

    meta = run["results"].get("meta", {})
    figs = {"tracking.png": tracking_figure(run["trials"], meta),
            "synchronization.png": synchronization_figure(run["trials"], meta),
            "criteria.png": criteria_figure(run["results"])}
    for name, fig in figs.items():
        fig.savefig(files_out.path(out / name), dpi=110)
    return list(figs)


def write_outputs(run: dict[str, Any], out: str | Path) -> Path:
    """results.json, report.md, tracking.png and criteria.png in ``out``, renamed
    into place together once all are written (atomic.FileSet: no half-written file)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with FileSet() as files:
        _write_all(run, out, files)
    return out


def _write_all(run: dict[str, Any], out: Path, files: FileSet) -> None:
    res = run["results"]
    files.write_text(out / "results.json", json.dumps(res, indent=2, allow_nan=True))
    _plots(run, out, files)
    meta = res["meta"]
    lines = ["# RTHS benchmark (Silva et al. 2020)", ""]
    if meta.get("label"):
        lines += [f"**{meta['label']}**", ""]
    noise = meta.get("noise", "simulink")
    official = "; seed 0 is the official run's realisation" if noise == "simulink" and meta["seed"] == 0 else ""
    lines += [f"- record: {meta['record']} × {meta['eq_intensity']} ({meta['record_source']})",
              f"- controller: {meta['controller']}: {meta['controller_description']}",
              f"- noise seed / perturbation seed: {meta['seed']} (noise generator: {noise}{official}); "
              f"perturbed runs per case: {meta['perturbed_runs']}",
              f"- CSI: {meta['csi']} ({'a2 dx/dt' if meta['csi'] == 'exact' else 'the code Derivative block'})",
              "- J in the official code's order (F4_evaluation.m): J1 [ms], J2-J9 [%]; PSI = log10(tau_cr / ms)",
              "- criteria: " + "; ".join(f"{n} = {label}" for n, label in zip(J_NAMES, J_LABELS)), ""]
    lines += [j_table(res), ""]
    flagged = [n for n, e in res["cases"].items() if e["nominal"]["max_force_N"] >= FORCE_LIMIT]
    lines += [f"Actuator capacity (max|f| >= {FORCE_LIMIT / 1e3:.1f} kN) exceeded in the nominal trial of case(s): "
              f"{', '.join(flagged) if flagged else 'none'}."]
    if "perturbed_stable" in meta:
        lines += [f"Perturbed trials that were stable (ran to the end with J2 < 100 %), per case: "
                  f"{meta['perturbed_stable']}; that ran to the end: {meta.get('perturbed_ran_to_end', {})}."]
    lines += ["", "![tracking](tracking.png)", "", "![synchronization](synchronization.png)", "",
              "![criteria](criteria.png)", ""]
    files.write_text(out / "report.md", "\n".join(lines))
