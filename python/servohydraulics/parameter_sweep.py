"""Parameter sweeps: grids or seeded Monte Carlo draws over rig parameters and
run options, executed in parallel through any ``concurrent.futures.Executor``.

Local processes are the default; a Dask cluster works through
``client.get_executor()`` (the same code path: ``submit`` and
``as_completed``, no scheduler of our own)::

    import servohydraulics as sh
    df = sh.sweep(grid={"controller.G_p": [0.5, 1.0, 2.0], "structure.m": [500.0, 7084.0]})

    from dask.distributed import Client
    with Client("tcp://scheduler:8786") as client:
        df = sh.sweep(grid=..., executor=client.get_executor())

A swept name with a dot that names a rig-file key (``"controller.G_p"``,
``"structure.m"``, ``"effects.coulomb_friction"``, ``"servovalve.flow_curve.b"``)
sets that rig parameter (SI units, as in the rig file); any other name is
passed as a keyword argument to the run function.  Each run function returns
a dict of summary metrics: one DataFrame row per run, the swept values first.

Compensator or test-method parameters are keyword arguments of a run
function of your own (top level in an importable module, so that workers
can unpickle it), e.g. the delay compensation T_ld against the damping::

    def rpsd_run(rig, delay_T):
        res = sh.run_rpsd(rig, ground_acceleration=AG, delay_T=delay_T, raise_on_failure=False)
        return {"peak_displacement": float(np.max(np.abs(res.channels["displacement"])))}

    sh.sweep(grid={"delay_T": [0.0, 5e-3, 11.2e-3], "structure.c": [1e3, 2.1e3]}, run=rpsd_run)
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import Executor, as_completed
from typing import Any, Callable

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from . import _core
from .excitations import sine
from .rig import EFFECTS, PARAMETERS, Rig, rig_from_dict, zhao2003
from .simulate import simulate, solver_options
from .workers import default_workers, process_pool

_RIG_KEYS = {f"{p.section}.{p.key}" for p in PARAMETERS} | {f"effects.{e}" for e in EFFECTS} | {
    "servovalve.flow_curve.b"}

__all__ = ["summary_run", "sweep", "grid_points", "monte_carlo_points"]


def summary_run(rig: Rig, mode: str = "displacement", command: ArrayLike | None = None,
                amplitude: float = 0.01, frequency: float = 1.0, duration: float = 2.0, dt: float = 5e-4,
                method: str = "dopri5", rtol: float | None = None, rk4_substeps: int = 0,
                keep_record: bool = False) -> dict[str, Any]:
    """The default run of a sweep: simulates the rig and returns summary metrics.

    Args:
        rig: the rig of this run.
        mode: ``"displacement"`` or ``"force"`` control.
        command: the command array [m or N]; None: a sine of ``amplitude``
            [m in displacement, N in force control] at ``frequency`` [Hz] for
            ``duration`` [s].
        dt: controller sample time [s].
        method, rtol, rk4_substeps: solver options (``solver_options``).
        keep_record: also return the full :class:`~servohydraulics.response.Response` under ``"record"``.

    Returns:
        ``ok`` (the run finished without diverging), ``status``, ``failure_time``
        [s], ``peak_displacement`` [m], ``peak_force`` [N] (load cell),
        ``rms_tracking_error`` and ``peak_tracking_error`` (command minus the
        fed-back channel: displacement [m] or load-cell force [N]),
        ``capacity_exceeded``, ``supply_limited``, ``spool_saturated``,
        ``internal_steps`` (the integrator's, whole run) and ``wall_time`` [s].
    """
    if command is None:
        command = sine(amplitude, frequency, duration, dt)
    options = solver_options(method=method, rtol=rtol, rk4_substeps=rk4_substeps)
    t0 = time.perf_counter()
    res = simulate(rig, mode=mode, command=command, dt=dt, options=options, raise_on_failure=False)
    wall = time.perf_counter() - t0
    measured = res.displacement if mode == "displacement" else res.force
    err = res.command - measured
    n = len(res.time)
    out: dict[str, Any] = {
        "ok": res.success,
        "status": res.work.status.message,
        "failure_time": math.nan if res.success else res.work.status.t,
        "peak_displacement": float(np.max(np.abs(res.displacement))) if n else math.nan,
        "peak_force": float(np.max(np.abs(res.force))) if n else math.nan,
        "rms_tracking_error": float(np.sqrt(np.mean(err**2))) if n else math.nan,
        "peak_tracking_error": float(np.max(np.abs(err))) if n else math.nan,
        "capacity_exceeded": res.capacity_exceeded,
        "supply_limited": res.supply_limited,
        "spool_saturated": bool(np.any(res.flags & _core.FLAG_SPOOL_SATURATED)),
        "internal_steps": int(res.work.internal_steps),
        "wall_time": wall,
    }
    if keep_record:
        out["record"] = res
    return out


def grid_points(grid: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """Every combination of the grid's values (last name varies fastest)."""
    names = list(grid)
    for name in names:
        values = grid[name]
        if isinstance(values, (str, bytes)) or not isinstance(values, Sequence) and not isinstance(
                values, np.ndarray):
            raise ValueError(f"invalid grid[{name!r}] = {values!r}: expected a sequence of values")
        if len(values) == 0:
            raise ValueError(f"invalid grid[{name!r}]: empty")
    return [dict(zip(names, combo)) for combo in itertools.product(*(list(grid[n]) for n in names))]


def monte_carlo_points(distributions: Mapping[str, Any], n: int, seed: int = 0) -> list[dict[str, Any]]:
    """``n`` seeded draws.  Each distribution is a frozen ``scipy.stats``
    distribution (anything with ``rvs(size=, random_state=)``) or a callable
    ``f(rng) -> value`` taking a ``numpy.random.Generator``."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"invalid n = {n!r}: the number of Monte Carlo draws must be an integer >= 1")
    rng = np.random.default_rng(seed)
    columns: dict[str, list[Any]] = {}
    for name, dist in distributions.items():  # one stream, names in the given order: reproducible
        if hasattr(dist, "rvs"):
            columns[name] = [float(v) for v in np.atleast_1d(dist.rvs(size=n, random_state=rng))]
        elif callable(dist):
            columns[name] = [dist(rng) for _ in range(n)]
        else:
            raise ValueError(f"invalid distributions[{name!r}] = {dist!r}: expected a scipy.stats "
                             "distribution or a callable f(rng)")
    return [{name: columns[name][i] for name in columns} for i in range(n)]


def _split(point: Mapping[str, Any]) -> tuple[dict[str, dict[str, Any]], dict[str, Any]]:
    """Rig overrides (nested like a rig file) and keyword arguments of one point."""
    rig_part: dict[str, dict[str, Any]] = {}
    kwargs: dict[str, Any] = {}
    for name, value in point.items():
        if name in _RIG_KEYS:
            if name == "servovalve.flow_curve.b":
                rig_part.setdefault("servovalve", {})["flow_curve"] = {"kind": "rational", "b": value}
            else:
                section, key = name.split(".", 1)
                if isinstance(value, np.generic):
                    value = value.item()
                rig_part.setdefault(section, {})[key] = value
        elif "." in name:
            raise ValueError(f"unknown rig key {name!r}: expected one of {sorted(_RIG_KEYS)} "
                             "(or a keyword argument of the run function, without a dot)")
        else:
            kwargs[name] = value
    return rig_part, kwargs


def _job(run: Callable[..., Mapping[str, Any]], base: Rig, rig_part: dict[str, Any],
         kwargs: dict[str, Any]) -> dict[str, Any]:
    """One run in a worker: the base rig (pickled) with the point's overrides, then the run function."""
    rig = rig_from_dict(rig_part, base=base)
    try:
        return dict(run(rig, **kwargs))
    except Exception as e:  # a failed run is a row, not a failed sweep
        return {"error": f"{type(e).__name__}: {e}"}


def sweep(grid: Mapping[str, Sequence[Any]] | None = None, *,
          distributions: Mapping[str, Any] | None = None, n: int | None = None, seed: int = 0,
          run: Callable[..., Mapping[str, Any]] = summary_run, rig: Rig | None = None,
          fixed: Mapping[str, Any] | None = None, executor: Executor | None = None,
          max_workers: int | None = None, progress: bool = True,
          keep_records: bool = False) -> pd.DataFrame:
    """Runs ``run(rig, **kwargs)`` over a grid or Monte Carlo draws, in parallel.

    Args:
        grid: name -> values; every combination is run.
        distributions: name -> scipy.stats frozen distribution or ``f(rng)``;
            ``n`` draws from one ``numpy`` generator seeded with ``seed``.
            Grid and draws combine: every grid point with every draw.
        run: the run function, a picklable top-level callable
            ``run(rig, **kwargs) -> dict`` of summary metrics (default
            ``summary_run``).  Exceptions become an ``error`` column.
        rig: the base rig (default: the calibrated ``zhao2003()`` preset).
        fixed: names set for every run (rig keys or keyword arguments).
        executor: any ``concurrent.futures.Executor``, e.g. a
            ``ProcessPoolExecutor`` or a Dask ``client.get_executor()``; the
            caller owns it.  None: a process pool of ``max_workers`` (1 ..
            ``os.cpu_count()``, default all) whose workers die with this
            process, created and shut down here.
        progress: show a tqdm progress bar.
        keep_records: keep a ``record`` column (only with ``summary_run``
            or a run function that returns one); otherwise it is dropped.

    Returns:
        One row per run, in the order of the points: the swept values
        (``fixed`` ones included), then the run's metrics.
    """
    if grid is None and distributions is None:
        raise ValueError("give a grid, distributions (with n), or both")
    if distributions is not None and n is None:
        raise ValueError("distributions need n, the number of Monte Carlo draws")
    points = grid_points(grid) if grid is not None else [{}]
    if distributions is not None:
        draws = monte_carlo_points(distributions, n, seed)  # type: ignore[arg-type]
        points = [{**p, **d} for p in points for d in draws]
    fixed = dict(fixed or {})
    if not callable(run):
        raise ValueError(f"invalid run = {run!r}: expected a callable run(rig, **kwargs) -> dict")
    base = rig if rig is not None else zhao2003()
    jobs = []
    for p in points:
        rig_part, kwargs = _split({**fixed, **p})
        if keep_records and run is summary_run:
            kwargs["keep_record"] = True
        if rig_part:  # validate here: a bad name or value fails before anything is submitted
            rig_from_dict(rig_part, base=base)
        jobs.append((rig_part, kwargs))

    own = executor is None
    if own:
        executor = process_pool(default_workers() if max_workers is None else max_workers, "max_workers")
    results: list[dict[str, Any] | None] = [None] * len(jobs)
    try:
        futures = {executor.submit(_job, run, base, rp, kw): i for i, (rp, kw) in enumerate(jobs)}
        bar = None
        if progress:
            from tqdm.auto import tqdm
            bar = tqdm(total=len(futures), desc="sweep", unit="run")
        for fut in as_completed(futures):
            results[futures[fut]] = fut.result()
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
    finally:
        if own:
            executor.shutdown(wait=True)
    rows = []
    for p, r in zip(points, results):
        r = dict(r or {})
        if not keep_records:
            r.pop("record", None)
        rows.append({**fixed, **p, **r})
    return pd.DataFrame(rows)
