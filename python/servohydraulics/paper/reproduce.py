"""``servohydraulics reproduce --out DIR``: the simulated counterpart of every
figure with results in Zhao, French, Shield & Posbergh (2003), and
``DIR/reproduction.md``: one row per quantitative statement of the paper, with
the paper's value, ours, the tolerance, agree or not, and why where not.

The paper's measured curves are not available: each figure says so, and the
comparison is to the numbers the paper states.  ``DIR/reproduction.json``
holds the same rows with their numeric acceptance intervals.

A section runs its experiments (experiments.py), evaluates its claims (claims.py,
evaluate.py) and draws its figures (figures.py); sections are independent and run
in a process pool.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

from ..atomic import check_folder
from ..rig import Rig, zhao2003
from ..workers import check_workers, default_workers, process_pool
from . import evaluate as ev
from . import experiments as xp
from . import figures
from .claims import CLAIMS
from .evaluate import Row
from .report import Reproduction, write_json, write_markdown

#: the experiments of each section: name -> function of (rig, quick) or of the results so far
SECTIONS = {
    "structure": {"fig2b_free_vibration": lambda rig, q, r: xp.fig2b_free_vibration(rig, q),
                  "forced_vibration": lambda rig, q, r: xp.forced_vibration(rig, q),
                  "equivalent_damping": lambda rig, q, r: xp.equivalent_damping(rig)},
    "force": {"fig3a_direct_eft": lambda rig, q, r: xp.fig3a_direct_eft(rig, q),
              "eq11_force_loop": lambda rig, q, r: xp.eq11_force_loop(rig),
              "fig4a_flow_curve": lambda rig, q, r: xp.fig4a_flow_curve(rig)},
    "eft": {"fig3_eft": lambda rig, q, r: xp.fig3_eft(rig)},
    "displacement": {"fig6a_amplitude_compensation": lambda rig, q, r: xp.fig6a_amplitude_compensation(rig),
                     "fig5_displacement_sweeps": lambda rig, q, r: xp.fig5_displacement_sweeps(rig, q),
                     "capacity_limit": lambda rig, q, r: xp.capacity_limit(rig, q)},
    "gain_bound": {"fig6b_gain_bound": lambda rig, q, r: xp.fig6b_gain_bound(rig, q)},
    "rpsd_linear": {"fig10_pole_zero": lambda rig, q, r: xp.fig10_pole_zero(rig)},
    "rpsd": {"fig9_free_vibration": lambda rig, q, r: xp.fig9_free_vibration(rig),
             "fig8_rpsd_delay": lambda rig, q, r: xp.fig8_rpsd_delay(rig),
             "fig9a_structural": lambda rig, q, r: xp.fig9a_structural(r["fig9_free_vibration"]),
             "fig9b_force_error": lambda rig, q, r: xp.fig9b_force_error(r["fig9_free_vibration"]),
             "fig10a_force": lambda rig, q, r: xp.fig10a_force(r["fig9_free_vibration"])},
    "table1": {"table1": lambda rig, q, r: xp.table1(rig)},
}

#: notes each section adds below the table
NOTES = {"structure": lambda r: [f"identification: free {r['fig2b_free_vibration'].estimate.nfev} simulations, "
                                 f"attached {r['forced_vibration'].estimate.nfev}"],
         "eft": ev.eft_notes, "gain_bound": ev.gain_bound_notes, "rpsd": ev.rpsd_notes}

#: expected relative cost of each section, to hand the longest ones out first
COST = {"eft": 10, "structure": 9, "rpsd": 8, "displacement": 5, "force": 3, "gain_bound": 1, "rpsd_linear": 1,
        "table1": 0}


def run_experiments(name: str, rig: Rig, quick: bool = False) -> dict:
    """The experiments of one section: experiment name -> its dataclass."""
    results: dict = {}
    for key, run in SECTIONS[name].items():
        results[key] = run(rig, quick, results)
    return results


def evaluate_section(name: str, results: dict) -> list[Row]:
    """The table rows of one section's claims."""
    return [ev.row(c, results) for c in CLAIMS[name]]


def _run_section(name: str, out: Path, quick: bool, rig: Rig) -> tuple[list, list, list, float]:
    """Runs one section (in a worker process or in-process) -> (rows, figures, notes, wall time [s])."""
    t0 = time.perf_counter()
    results = run_experiments(name, rig, quick)
    rows = evaluate_section(name, results)
    paths = figures.draw(name, results, rig, out)
    notes = NOTES[name](results) if name in NOTES else []
    return rows, paths, notes, time.perf_counter() - t0


def _check(names: list, workers) -> None:
    for n in names:
        if n not in SECTIONS:
            raise ValueError(f"invalid section = {n!r}: expected one of {list(SECTIONS)}")
    check_workers(workers)


def _run_all(names: list, out: Path, quick: bool, rig: Rig, workers: int, progress: bool) -> dict:
    """Runs the sections, the costliest first, in this process or a pool -> name -> _run_section's tuple."""
    from concurrent.futures import as_completed

    from tqdm import tqdm

    results: dict = {}
    order = sorted(names, key=lambda n: -COST.get(n, 1))
    with tqdm(total=len(names), desc="reproduce", unit="section", disable=not progress) as bar:
        if workers == 1 or len(names) == 1:
            for n in order:
                results[n] = _run_section(n, out, quick, rig)
                bar.update()
        else:
            with process_pool(min(workers, len(names))) as pool:
                futures = {pool.submit(_run_section, n, out, quick, rig): n for n in order}
                for fut in as_completed(futures):
                    results[futures[fut]] = fut.result()
                    bar.set_postfix_str(futures[fut])
                    bar.update()
    return results


def reproduce(out: str | Path = "reproduction", quick: bool = False, sections: Sequence[str] | None = None,
              progress: bool = True, rig: Rig | None = None, workers: int | None = None) -> Reproduction:
    """Regenerates every figure and ``reproduction.md`` / ``reproduction.json`` in ``out``.

    quick: shorter sweeps in the structure and displacement sections (for tests; the
    test-method sections always use the 20 s sweeps their rows need); sections: subset
    of the section names (default all); rig: default the calibrated preset; workers:
    processes running independent sections at once (1: all in this process; 1 ..
    os.cpu_count(), default 2 or the machine's processors if fewer).
    """
    t0 = time.perf_counter()
    out = Path(out)
    names = list(SECTIONS) if sections is None else list(sections)
    workers = default_workers(2) if workers is None else workers
    _check(names, workers)
    check_folder(out)  # a folder that cannot take the outputs fails now, not after the computation
    results = _run_all(names, out, quick, rig if rig is not None else zhao2003(), workers, progress)
    rows, paths, notes = [], [], []
    for n in names:  # the table's order does not depend on which worker finished first
        rows += results[n][0]
        paths += results[n][1]
        notes += results[n][2]
    rep = Reproduction(rows=rows, figures=paths, runtime=time.perf_counter() - t0,
                       section_times={n: results[n][3] for n in names})
    write_markdown(rep, out / "reproduction.md", notes)
    write_json(rep, out / "reproduction.json")
    return rep


__all__ = ["SECTIONS", "Reproduction", "Row", "evaluate_section", "reproduce", "run_experiments"]
