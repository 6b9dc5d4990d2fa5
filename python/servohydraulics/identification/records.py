"""``sh.identify``: a rig identified from its own lab records.

``identify(records, rig=start, fit=[keys], mode=...)`` fits the chosen rig keys
to one or more records in two stages (``fitting.py``: the frequency response
on the linearised model, then the time domain on the nonlinear simulation)
and returns an :class:`Identification`: the identified rig, each key's value,
status, 95 % interval and the correlation matrix (the HAC sandwich of
:mod:`.stats` at the optimum, the rule ``sh.diagnose`` uses too), the pairs the
data cannot separate, and the comparison of every record before and after.

The result is never worse than the start: the start, the frequency stage and the
time stage are compared by the time-domain cost and the best is kept (a fit that
cannot improve on its start says so in ``flags``).  A key the records do not
determine, or one that ends at a bound of its coordinates (or collapses towards
zero), has status ``"not identified"`` / ``"at bound"`` and an interval over its
whole range, never a falsely precise one.  ``Identification.write(out)`` writes ``rig_identified.toml``,
``identification.json``, ``report.md`` and per-record overlay and FRF plots.

Without a start rig, :func:`~servohydraulics.identification.generic.generic_rig` scales
one from the first record.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import FileSet, check_folder
from ..records import read_record
from ..response import Response
from ..rig import Rig, load_rig, save_rig
from ..workers import single_blas_thread
from .checks import check_accept, gate
from .compare import Comparison, channels_of, compare, save_figures, write_json
from .coordinates import FORCE_KEYS, LOOP_KEYS, Coordinates, check_keys, specimen_keys, use_specimen
from .fit import (
    RK4_SUBSTEPS,
    StageResult,
    automatic_substeps,
    best,
    channel_weights,
    checked_options,
    default_workers,
    fit_frequency,
    fit_options,
    fit_time,
    keep_best,
    not_improved_flags,
    rk4_options,
    time_costs,
    time_residual,
)
from .generic import generic_rig, record_scales, specimen_start
from .law import (
    MR_LAWS,
    FieldInput,
    check_law,
    coordinate_scales,
    field_input,
    law_keys,
    law_start,
    start_range,
    with_fields,
)
from .run import check_record, controller_ratio, simulate_record
from .segments import AGREEMENT, Target, whole
from .stats import (
    LEVEL,
    ar1_coefficient,
    ar1_effective_n,
    bound_status,
    covariance,
    inseparable_groups,
    quantile,
)


@dataclass(eq=False)
class Identification:
    """The outcome of :func:`identify` (SI units)."""

    rig: Rig  #: the identified rig
    start: Rig  #: the start (given or generic)
    mode: str
    keys: tuple[str, ...]
    values: dict  #: key -> identified value
    start_values: dict  #: key -> start value
    stage1_values: dict  #: key -> value after the frequency-domain stage (None: not fitted there)
    intervals: dict  #: key -> (low, high), 95 % (the key's whole range unless its status is "identified")
    std: dict  #: key -> standard error (linearised; inf unless identified)
    correlation: np.ndarray = field(repr=False)
    flags: list = field(default_factory=list)  #: what the data cannot separate or determine
    before: list = field(default_factory=list, repr=False)  #: Comparison per record, start rig
    after: list = field(default_factory=list, repr=False)  #: Comparison per record, identified rig
    generic_start: bool = False
    n_eff: float = 0.0
    rho1: float = 0.0
    nfev: dict = field(default_factory=dict)
    runtime_s: dict = field(default_factory=dict)
    weights: dict = field(default_factory=dict)  #: channel -> weight of its normalised residual
    integrator: str = "rk4"
    status: dict = field(default_factory=dict)  #: key -> "identified", "not identified" or "at bound"
    costs: dict = field(default_factory=dict)  #: time-domain cost of the start and of each stage
    kept: str = "time"  #: which of "start", "frequency", "time" the result is
    checks: list = field(default_factory=list)  #: ``checks.Check``: the records' plausibility, the runs' limits
    field_input: FieldInput | None = None  #: the MR damper's field per record (``currents=``/``voltages=``)
    law: str | None = None  #: the MR damper's field law fitted across the records (``law.py``)
    #: how the time stage ran the records (``segments.Target``): its integrator, the segments per
    #: record (1: whole runs), whether the result was polished on the pair's whole runs
    runs: dict = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        units = _units()
        return {
            "mode": self.mode, "generic_start": self.generic_start, "level": LEVEL,
            "parameters": {k: {"value": self.values[k], "unit": units.get(k, "?"), "start": self.start_values[k],
                               "stage1": self.stage1_values[k], "std": self.std[k],
                               "status": self.status.get(k, "identified"),
                               "interval": list(self.intervals[k])} for k in self.keys},
            "correlation": {"keys": list(self.keys), "matrix": np.round(self.correlation, 4).tolist()},
            "derived": derived(self.rig, self.mode), "flags": self.flags, "channel_weights": self.weights,
            "integrator": self.integrator, "n_eff": self.n_eff, "rho1": self.rho1, "nfev": self.nfev,
            "runtime_s": self.runtime_s, "runs": self.runs, "costs": self.costs, "kept": self.kept,
            "checks": [c.to_dict() for c in self.checks],
            "field": None if self.field_input is None else {**self.field_input.to_dict(), "law": self.law},
            "records": [{"record": b.name, "before": {c: b.channels[c]["nrmse_pct"] for c in b.channels},
                         "after": {c: a.channels[c]["nrmse_pct"] for c in a.channels}, "warnings": a.warnings,
                         **({} if self.field_input is None else
                            {self.field_input.kind: self.field_input.values[i]})}
                        for i, (b, a) in enumerate(zip(self.before, self.after))],
        }

    def markdown(self) -> str:
        from .report import identification_markdown

        return identification_markdown(self)

    def write(self, out: str | Path) -> Path:
        """Writes the rig, the JSON and markdown report and the plots into ``out``, as one
        ``atomic.FileSet``: all of them, or (an OSError naming the file) none."""
        out = check_folder(out)
        figs = {out / f"{name}_{a.name}.png": fig for a in self.after for name, fig in a.figures().items()}
        with FileSet() as files:
            save_figures(files, figs)
            save_rig(self.rig, files.path(out / "rig_identified.toml"))
            write_json(out / "identification.json", self.to_dict(), files)
            files.write_text(out / "report.md", self.markdown())
        return out / "report.md"


def derived(rig: Rig, mode: str) -> dict[str, float]:
    """What the records determine even where the keys trade off: the loop gain
    G_p C_F K_s K_v / A [1/s] in displacement control (the closed-loop corner of
    the integrating loop; a generic start's G_p alone depends on its scaling)."""
    if mode != "displacement":
        return {}
    return {"loop_gain_1_per_s": float(rig.G_p * rig.C_F_disp * rig.K_s * rig.K_v / rig.A),
            "valve_lag_s": float(2.0 * rig.zeta_v / (2.0 * np.pi * rig.f_v))}


def _units() -> dict[str, str]:
    from ..rig import PARAMETERS

    return {p.key: p.unit for p in PARAMETERS}


def as_records(records, layout=None) -> list:
    """Records from records (anything with ``channels``: a Response) or record paths (a single
    one is accepted); the paths read by ``read_record`` with ``layout`` (a ``readers.Layout``,
    a layout file or a dict of its fields: columns, units, scale...)."""
    if isinstance(records, (str, Path)) or hasattr(records, "channels"):
        records = [records]
    out = [r if hasattr(r, "channels") else read_record(r, layout) for r in records]
    if not out:
        raise ValueError("invalid records = []: give at least one record")
    return out


def _start_rig(rig, records: list[Response], scale_from_largest_force: bool = False) -> tuple[Rig, bool]:
    """The start: ``rig`` (a Rig or a rig file), or the generic rig scaled from the first record
    (``scale_from_largest_force``: from the record of the largest peak force, so that a damper's
    strongest record sizes the generic actuator, whose load-pressure term scales with F / F_cap)."""
    if rig is None:
        if scale_from_largest_force:
            return generic_rig(max(records, key=lambda r: record_scales(r)["F_pk"])), True
        return generic_rig(records[0]), True
    if isinstance(rig, (str, Path)):
        return load_rig(rig), False
    return copy.copy(rig), False


#: a log-coordinate key below this fraction of its start has collapsed towards zero
COLLAPSED = 1e-6


def key_status(coords: Coordinates, z: np.ndarray, identified: np.ndarray) -> list[str]:
    """Per key: "at bound" (within 1e-6 of a bound of its coordinates, ``stats.bound_status``, or a
    log key below ``COLLAPSED`` times its start), else "not identified" (``stats.covariance``), else
    "identified"."""
    lo, hi = coords.bounds()
    status = bound_status(z, lo, hi, identified)
    collapsed = np.asarray(coords.log) & (np.asarray(z) < np.log(COLLAPSED))
    return ["at bound" if c else s for s, c in zip(status, collapsed)]


#: the chi-square 95 % point with one degree of freedom: a key whose removal (its value set to the
#: bottom of its range) raises the cost by less than this, in units of its sandwich variance, is
#: indistinguishable from zero
CHI2_1_95 = 3.841458820694124


def removal_statistics(stage: StageResult, coords: Coordinates, cov, residual, fast=None) -> dict[int, float]:
    """For each log key the fit left "identified": the test statistic of "the key is zero", from a
    simulation with the key removed (at the bottom of its log range) rather than from the Jacobian.

    In log coordinates the Jacobian column J_i is the linearised change of the residual when the key
    goes from its value to zero, and the sandwich's Wald statistic of "zero" is 1 / sd_i^2.  The
    statistic here scales that by the simulated change over the linearised one,
    W_i = (2 dC_i / |J_i|^2) / sd_i^2 (dC_i: the rise of the cost, half the sum of squares): equal
    to the Wald statistic where the linearisation holds, and small where the key's value no longer
    does anything (a damper mass collapsed to 3.6e-11 kg, whose Jacobian column is the integrator's
    noise and whose sandwich interval came out 6e-15 kg wide).  ``residual(z)`` gives the
    weighted residual of ``stage.fun`` at z (whole runs: the cost at ``stage.z`` is recomputed with
    it, so that an integrator's difference from the fit's runs does not count as a rise).
    ``fast(points)`` (optional) gives it at several points at once on cheaper runs (the fit's own),
    None at a point where those cannot stand for it; each removal is then compared with the cost at
    ``stage.z`` on the same runs as its own, ``residual``'s only where ``fast`` gave None."""
    from concurrent.futures import ThreadPoolExecutor

    lo, _ = coords.bounds()
    sd = cov.sd
    cols = {int(i): float(stage.jac[:, i] @ stage.jac[:, i])
            for i in np.flatnonzero(np.asarray(coords.log) & cov.identified)}
    todo = [i for i, c in cols.items() if c > 0.0 and np.isfinite(sd[i]) and sd[i] > 0.0]
    z0 = np.asarray(stage.z, dtype=float)
    points = {}
    for i in todo:
        points[i] = z0.copy()
        points[i][i] = lo[i]

    def statistic(i: int, r: np.ndarray, cost0: float) -> float:
        return float((2.0 * max(0.5 * float(r @ r) - cost0, 0.0) / cols[i]) / sd[i] ** 2)

    out: dict[int, float] = {}
    if fast is not None and todo:
        r0, *rs = fast([z0] + [points[i] for i in todo])
        if r0 is not None:
            out = {i: statistic(i, r, 0.5 * float(r0 @ r0)) for i, r in zip(todo, rs) if r is not None}
    rest = [i for i in todo if i not in out]
    if rest:
        r0 = residual(z0)  # the same runs as these removals' (not the fit's segments)
        cost0 = 0.5 * float(r0 @ r0)
        with ThreadPoolExecutor(max_workers=default_workers()) as pool:  # the core releases the GIL
            out.update(zip(rest, pool.map(lambda i: statistic(i, residual(points[i]), cost0), rest)))
    return {i: out[i] for i in todo}


def uncertainty(stage: StageResult, coords: Coordinates, lengths: list[int], cov=None, residual=None, fast=None
                ) -> dict[str, Any]:
    """The HAC covariance (``stats.covariance``; ``cov`` when already computed) of the fit in its
    coordinates and, per key, its status, standard error and 95 % interval in the key's unit; plus
    the correlation matrix and the AR(1) summary of the residual (lag-1 rho, effective samples).
    With ``residual`` (z -> the weighted residual of the fit), a log key whose removal the records
    cannot tell from its value (``removal_statistics`` below ``CHI2_1_95``) is "at bound" (collapsed
    to zero) as well (``fast``: ``removal_statistics``' cheaper runs)."""
    cov = covariance(stage.jac, stage.fun, None, lengths) if cov is None else cov
    status = key_status(coords, stage.z, cov.identified)
    removal = removal_statistics(stage, coords, cov, residual, fast) if residual is not None else {}
    for i, w in removal.items():
        if status[i] == "identified" and w < CHI2_1_95:
            status[i] = "at bound"
    zq, sd_z = quantile(LEVEL), cov.sd
    intervals, std = {}, {}
    for i, k in enumerate(coords.keys):
        if status[i] == "identified":
            intervals[k] = coords.interval(stage.z[i], sd_z[i], i, zq)
            std[k] = coords.value_sd(i, stage.z[i], sd_z[i])
        else:  # no falsely precise interval: the key's whole range
            intervals[k] = coords.interval(stage.z[i], np.inf, i, zq)
            std[k] = float("inf")
    rho = ar1_coefficient(stage.fun)
    return {"status": dict(zip(coords.keys, status)), "intervals": intervals, "std": std,
            "correlation": cov.correlation, "rho1": rho, "n_eff": ar1_effective_n(stage.fun.size, rho),
            "removal": {coords.keys[i]: w for i, w in removal.items()}}


def separability_flags(keys, values: dict, intervals: dict, corr: np.ndarray, status: dict | None = None) -> list[str]:
    """Keys the records do not determine or that ended at a bound, the groups of keys the records
    cannot tell apart (``stats.inseparable_groups``: linked by |corr| > 0.95) and keys whose 95 %
    interval is wider than the value."""
    status = status or {}
    flags = [f"{k} is {status[k]}: the records do not determine it (its interval is its whole range)"
             if status[k] == "not identified" else
             f"{k} is at a bound of its range (or collapsed towards zero) at {values[k]:.4g}: at bound / not "
             "identified, its interval is its whole range" for k in keys if status.get(k, "identified") != "identified"]
    keys = list(keys)
    c = np.asarray(corr, dtype=float)
    for g in inseparable_groups(c):
        top = max(abs(c[i, j]) for i in g for j in g if i != j)
        flags.append(f"{' and '.join(keys[i] for i in g)} cannot be separated by these records (a group: "
                     f"|correlation| up to {top:.3f}; only a combination of them is determined)")
    for k in keys:
        lo, hi = intervals[k]
        if status.get(k, "identified") == "identified" and hi - lo > abs(values[k]):
            flags.append(f"{k} is poorly determined: its 95 % interval [{lo:.4g}, {hi:.4g}] is wider than its "
                         f"value {values[k]:.4g}")
    return flags


def time_blocks(keys: tuple[str, ...], channels: tuple[str, ...], mode: str) -> list[tuple[np.ndarray, tuple]]:
    """The time-domain stage's blocks (active keys, channels fitted), in order.  In
    displacement control with both channels: the loop's keys (every key that is not a
    force key, ``FORCE_KEYS``) on the displacement, then the force keys on the force (the
    specimen sees the displacement the loop makes; the records show a tracking that does
    not depend on the load).  Otherwise one block: every key on every channel."""
    force = np.array([k in FORCE_KEYS for k in keys])
    if mode == "displacement" and set(channels) >= {"displacement", "force"} and force.any() and not force.all():
        return [(~force, ("displacement",)), (force, ("force",))]
    return [(np.ones(len(keys), dtype=bool), channels)]


#: block sweeps of the time stage at most.  A block fit has moved when a key moved by more than
#: SWEEP_TOL in its fitting coordinate and by more than SWEEP_SD of its standard error (the block
#: fit's HAC covariance, the other blocks held): the loop keys fitted on the displacement with a
#: wrong specimen compensate for its force (the load does change the tracking), so the blocks are
#: swept again with the specimen's new keys until none moves (block coordinate descent); a move
#: below the records' resolution calls for no further sweep (a key the records do not determine,
#: such as a damper's beta collapsing towards 0, wanders by units of log without changing the fit)
MAX_SWEEPS, SWEEP_TOL, SWEEP_SD = 4, 2e-3, 0.1


def _moved(s: StageResult, z_before: np.ndarray, active: np.ndarray, lengths: list[int]) -> bool:
    """Whether a block fit moved a key beyond ``SWEEP_TOL`` and ``SWEEP_SD`` of its standard error."""
    dz = np.abs(s.z - z_before)[active]
    sd = covariance(s.jac, s.fun, None, lengths).sd if s.jac is not None else np.zeros(dz.size)
    sd = np.where(np.isfinite(sd), sd, np.inf)  # a key the records do not determine: no move counts
    return bool(np.any((dz > SWEEP_TOL) & (dz > SWEEP_SD * sd)))


def _time_stage(target: Target, start, coords, z1, mode, chans, max_nfev, bar):
    """Stage 2 block by block (:func:`time_blocks`) on ``target``'s runs, the blocks swept until
    the last fits of all but one block did not move (``_moved``; the block fitted before them is
    then at its optimum for the others' values) or ``MAX_SWEEPS``; returns the stage's z and its
    evaluations."""
    z = np.array(z1, dtype=float)
    blocks = time_blocks(coords.keys, chans, mode)
    if len(blocks) == 1:
        active, block_chans = blocks[0]
        w = channel_weights(target, coords.apply(start, z), block_chans)
        s = fit_time(target, start, coords, z, block_chans, max_nfev, bar, w, active)
        return s.z, s.nfev
    nfev, quiet = 0, 0
    for sweep in range(MAX_SWEEPS):
        for b, (active, block_chans) in enumerate(blocks):
            s = fit_time(target, start, coords, z, block_chans, max_nfev, bar, None, active)
            quiet = 0 if _moved(s, z, active, target.lengths_of(block_chans)) else quiet + 1
            z, nfev = s.z, nfev + s.nfev
            if (sweep > 0 or b == len(blocks) - 1) and quiet >= len(blocks) - 1:
                return z, nfev
    return z, nfev


def _field_setup(recs: list, specimen: str | None, currents, voltages, law: str | None
                 ) -> tuple[list, str, FieldInput | None, str | None]:
    """(records with their field values, specimen, field input, law), validated: the field
    (``law.field_input``) needs the MR damper, a law needs the field."""
    field_in = field_input(recs, currents, voltages)
    if field_in is None:
        if law is not None:
            raise ValueError(f"invalid law = {law!r}: a field law needs the records' field values (currents= or "
                             "voltages=, --current or --voltage)")
        return recs, specimen or "linear", None, None
    if specimen not in (None, "mr_damper"):
        raise ValueError(f"invalid specimen = {specimen!r} with {field_in.kind}s: the field per record drives an MR "
                         "damper's law; use specimen 'mr_damper'")
    return with_fields(recs, field_in), "mr_damper", field_in, check_law(law or "spencer")


def _setup(records, rig, fit, mode: str, specimen: str | None, channels, dt: float | None = None,
           currents=None, voltages=None, law: str | None = None) -> tuple[list, Rig, bool, tuple, tuple, dict]:
    """(records, start rig, generic start?, keys, channels, field setup), validated (with the
    controller ``dt``); the field setup: ``field`` (FieldInput or None), ``law``, ``notes`` (the
    law's coefficients held), ``scales`` (coordinate scales of the keys that may start at 0)."""
    if mode not in LOOP_KEYS:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(LOOP_KEYS)}")
    recs = [check_record(r) for r in as_records(records)]
    for r in recs:
        controller_ratio(r.dt, r.time.size, dt)
    recs, specimen, field_in, law = _field_setup(recs, specimen, currents, voltages, law)
    spec = specimen_keys(specimen)
    x = np.asarray(recs[0].displacement, dtype=float)
    if rig is None and np.ptp(x) == 0:  # the generic start scales from the motion
        raise ValueError(f"{recs[0].path or 'record'}: invalid displacement = constant {float(x[0])!r}: the generic "
                         "start scales the rig from the motion; give a start rig")
    start, generic = _start_rig(rig, recs, scale_from_largest_force=field_in is not None)
    extra = {"field": field_in, "law": law, "notes": [], "scales": None}
    if field_in is not None:
        use_specimen(start, specimen)
        if generic:
            law_start(start, recs, field_in, law)
        else:
            start.mr_law = MR_LAWS[law]
            start_range(start, field_in)
        spec, extra["notes"] = law_keys(law, field_in.levels)
        extra["scales"] = coordinate_scales(start, field_in)
        start.validate()
    elif generic:
        specimen_start(start, recs[0], specimen)
    use_specimen(start, specimen)
    keys = check_keys(start, fit if fit is not None else LOOP_KEYS[mode] + spec)
    chans = tuple(channels) if channels is not None else channels_of(recs[0], mode)
    for r in recs:
        missing = [c for c in chans if c not in channels_of(r, mode)]
        if missing:
            raise ValueError(f"record {r.path or '?'}: channel(s) {missing} absent or constant")
    return recs, start, generic, keys, chans, extra


def _fit_target(recs, start, coords, z1, mode, chans, options, dt, workers, before: list) -> Target:
    """The runs of the time stage: the records in segments (``segments.Target``) through RK4 at the
    fewest substeps of ``fit.RK4_SUBSTEPS`` whose run of the start agrees with the pair's whole runs
    ``before`` (``Target.agrees``), else through the pair (``options``), else the pair's whole runs."""
    rig1 = coords.apply(start, z1)
    for n in RK4_SUBSTEPS:
        target = Target.build(recs, mode, chans, rk4_options(n), dt, rig1, workers)
        if target.agrees(start, before):
            return target
        target.close()
    target = Target.build(recs, mode, chans, options, dt, rig1, workers)
    if target.agrees(start, before):
        return target
    target.close()
    return Target(recs, mode, chans, options, dt, [whole(r) for r in recs], workers)


def _time_stages(recs, start, coords, z1, frequency_stage, mode, chans, options, dt, max_nfev, progress, workers,
                 before: list):
    """Stage 2 from stage 1's z1 (again from the start when that ends worse than the start), then
    ``fit.keep_best`` of the start and the stages, on the runs of ``_fit_target`` (checked against
    the pair's whole runs ``before`` of the start, and against those of the result: where they
    disagree the result is polished on the pair's whole runs); returns keep_best's result, the
    evaluations, the whole runs of the result, how the time stage ran (``Identification.runs``), the
    result's ``stats.covariance``, and the options and segments of the runs the result stands on."""
    from tqdm.auto import tqdm

    workers = default_workers() if workers is None else max(1, int(workers))
    target = _fit_target(recs, start, coords, z1, mode, chans, options, dt, workers, before)
    runs = {"integrator": _describe(target.options), "segments": [len(segs) for segs in target.segments],
            "shift_sd": 0.0, "polished_on_whole_runs": False}
    with tqdm(desc="identify (simulations)", unit="sim", disable=not progress, leave=False) as bar:
        try:
            stages = {"start": np.zeros(len(coords.keys)), "frequency": z1} if frequency_stage else {"start": z1}
            stages["time"], nfev = _time_stage(target, start, coords, z1, mode, chans, max_nfev, bar)
            if frequency_stage and best(time_costs(target, start, coords, stages)) != "time":
                stages["time"], n = _time_stage(target, start, coords, stages["start"], mode, chans, max_nfev, bar)
                nfev += n
            kept = keep_best(target, start, coords, stages, bar)
            after = _whole_runs(coords.apply(start, kept[3].z), recs, mode, dt, checked_options(options), workers)
            cov = covariance(kept[3].jac, kept[3].fun, None, target.lengths)
            runs["shift_sd"] = _shift(target, coords.apply(start, kept[3].z), after, kept[2], kept[3], cov)
            if not runs["shift_sd"] <= SHIFT_SD:  # polish on the pair's whole runs
                target.close()
                target = Target(recs, mode, chans, options, dt, [whole(r) for r in recs], workers)
                runs["polished_on_whole_runs"] = True
                stages["time"], n = _time_stage(target, start, coords, kept[3].z, mode, chans, max_nfev, bar)
                nfev += n
                kept = keep_best(target, start, coords, stages, bar)
                after = _whole_runs(coords.apply(start, kept[3].z), recs, mode, dt, checked_options(options), workers)
                cov = covariance(kept[3].jac, kept[3].fun, None, target.lengths)
        finally:
            target.close()
    return (*kept, nfev, after, runs, cov, (target.options, target.segments))


#: the time stage's result stands when the pair's whole runs would move it by at most this fraction
#: of each identified key's standard error (``_shift``); else it is polished on them
SHIFT_SD = 0.1


def _shift(target: Target, rig, after: list, weights: dict, final: StageResult, cov) -> float:
    """How far the pair's whole runs ``after`` of the result would move it, in standard errors: the
    Gauss-Newton step from the target's residual to theirs, (J'J)^+ J' d with d the difference of the
    two weighted residuals at the result and J the result's Jacobian, over each identified key's
    standard error (``stats.covariance``, the rule of the reported intervals); the largest, inf when
    a run failed or differs by more than 10 ``segments.AGREEMENT`` somewhere.  ``cov``: the
    result's ``stats.covariance``."""
    d = target.residual(rig, weights) - target.of(after, weights)
    if not np.all(np.isfinite(d)) or np.max(np.abs(d)) > 10 * AGREEMENT * max(weights.values()):
        return float("inf")
    step = np.linalg.lstsq(final.jac, d, rcond=None)[0]
    sd = cov.sd
    ok = np.isfinite(sd) & (sd > 0)
    return float(np.max(np.abs(step[ok]) / sd[ok])) if ok.any() else 0.0


def _removal_runs(target: Target, start: Rig, coords: Coordinates, z_fit: np.ndarray, recs: list, mode: str,
                  weights: dict):
    """``removal_statistics``' cheaper runs: the time stage's own (RK4 on the records' segments, shown to
    agree with the pair's whole runs at the start and at the result: ``Target.agrees``, ``_shift``), for a
    removal whose rig is no stiffer than the result (RK4's automatic substep count, from the plant's rate
    bound, at most the result's: on the UTFSM chirp the damper's c1 removed is stiffer, and goes to the
    pair) and whose run does not fail; None when the time stage ran on the pair."""
    if target.options.method.name.lower() != "rk4":
        return None
    n_fit = automatic_substeps(coords.apply(start, z_fit), recs, mode)

    def fast(points: list) -> list:
        rigs = []
        for z in points:
            try:
                rig = coords.apply(start, z)
            except ValueError:  # not a valid rig: the pair's runs decide
                rig = None
            n = None if rig is None or n_fit is None else automatic_substeps(rig, recs, mode)
            rigs.append(rig if n is not None and n <= n_fit else None)
        done = iter(target.completed([r for r in rigs if r is not None], weights))
        return [None if r is None else next(done) for r in rigs]

    return fast


def _describe(options) -> str:
    """The integrator of a set of solver options, as the report names it."""
    name = options.method.name.lower()
    if name == "rk4":
        return f"rk4, {options.rk4_substeps} substeps per sample"
    return f"{name}, rtol {options.rtol:g}"


def _whole_runs(rig, recs, mode, dt, options, workers) -> list:
    """``simulate_record`` of every record through the rig (whole runs), on ``workers`` threads."""
    from concurrent.futures import ThreadPoolExecutor

    if workers <= 1 or len(recs) <= 1:
        return [simulate_record(rig, r, mode, dt=dt, options=options) for r in recs]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(lambda r: simulate_record(rig, r, mode, dt=dt, options=options), recs))


@single_blas_thread  # the simulations' threads need the cores (workers.blas_threads)
def identify(records, rig: Rig | str | Path | None = None, fit: Sequence[str] | None = None,
             mode: str = "displacement", specimen: str | None = None, channels: Sequence[str] | None = None,
             dt: float | None = None, frequency_stage: bool = True, max_nfev: int = 60,
             progress: bool = True, workers: int | None = None, layout=None, accept=None,
             currents: Sequence[float] | None = None, voltages: Sequence[float] | None = None,
             law: str | None = None) -> Identification:
    """Identifies rig keys from lab records (see the module docstring).

    Args:
        records: record paths or Responses (time, command, displacement, force).
        rig: the start (a Rig or a rig TOML path); None: the generic rig scaled from the first record.
        fit: keys to fit; default ``LOOP_KEYS[mode]`` + ``SPECIMEN_KEYS[specimen]``.
        mode: the records' control mode, ``"displacement"`` or ``"force"``.
        specimen: ``"linear"`` (the default), ``"bouc_wen"`` or ``"mr_damper"`` (``keys.SPECIMEN_KEYS``; a
            generic start scales the specimen from the record, ``generic.specimen_start``); with
            ``currents``/``voltages`` ``"mr_damper"`` (the default then).
        channels: the channels fitted (default: those the records carry, displacement and force).
        dt: controller sample time [s] (default: the records' own).
        frequency_stage: run stage 1 (the H1 fit of the linearised model) before the time domain.
        max_nfev: the time-domain stage's budget of residual evaluations (Jacobians not counted).
        progress: a tqdm bar over the simulations.
        workers: threads for the Jacobian's columns (default: up to 2).
        layout: how record paths are read (``read_record``'s ``layout``: a ``readers.Layout``, a
            layout file or a dict of its fields, e.g. ``{"units": {"displacement": "mm"}}``).
        accept: codes of warning-level checks acknowledged (``checks.CODES``).  The records are
            checked against the start rig (a generic start: the rig-free checks only) before any
            fit; an error-level check raises ``checks.CheckError`` (a ValueError).
        currents: an MR damper's coil current [A] per record, in order (``law.py``): one rig fitted to
            all the records, each simulated at its own current; the damper's law coefficients are the
            fitted keys (``law.law_keys``).  ValueError: a count that does not match the records, a
            value that is not a finite number >= 0, or ``voltages`` as well.
        voltages: the same for a voltage-driven damper [V].
        law: the field law, ``"spencer"`` (linear, the default) or ``"quiroz2022"`` (the UTFSM
            thesis': alpha quadratic, beta and gamma decaying exponentially); needs the field.
    """
    if isinstance(max_nfev, bool) or not isinstance(max_nfev, (int, np.integer)) or max_nfev < 1:
        raise ValueError(f"invalid max_nfev = {max_nfev!r}: must be an integer >= 1")
    t_start = time.perf_counter()
    check_accept(accept)
    recs, start, generic, keys, chans, extra = _setup(as_records(records, layout), rig, fit, mode, specimen,
                                                      channels, dt, currents, voltages, law)
    found = gate(recs, None if generic else start, mode, dt, accept)
    coords = Coordinates.about(start, keys, extra["scales"])
    runtime: dict[str, float] = {}
    z1, stage1_keys, nfev = np.zeros(len(keys)), [], {}
    if frequency_stage:
        t0 = time.perf_counter()
        s1, stage1_keys = fit_frequency(recs, start, coords, mode, chans)
        z1, nfev["frequency"], runtime["frequency"] = s1.z, s1.nfev, time.perf_counter() - t0
    options = fit_options(coords.apply(start, z1), recs, mode)
    t0 = time.perf_counter()
    before_runs = _whole_runs(start, recs, mode, dt, options, default_workers() if workers is None else workers)
    kept, costs, weights, final, nfev["time"], after_runs, runs, cov, (stage_options, stage_segments) = _time_stages(
        recs, start, coords, z1, frequency_stage, mode, chans, options, dt, max_nfev, progress, workers, before_runs)
    runtime["time"] = time.perf_counter() - t0
    lengths = [r.time.size for r in recs for _ in chans]
    with Target(recs, mode, chans, stage_options, dt, stage_segments,
                default_workers() if workers is None else max(1, int(workers))) as fit_runs:
        u = uncertainty(final, coords, lengths, cov,
                        residual=lambda z: time_residual(coords.apply(start, z), recs, mode, chans, options, dt,
                                                         weights),
                        fast=_removal_runs(fit_runs, start, coords, final.z, recs, mode, weights))
    values = {k: float(v) for k, v in zip(keys, coords.values(final.z))}
    s1_vals = coords.values(z1)
    out_rig = coords.apply(start, final.z)
    t0 = time.perf_counter()
    before = [compare(r, start, mode, simulated=sim, check=False) for r, sim in zip(recs, before_runs)]
    after = [compare(r, out_rig, mode, simulated=sim, accept=accept, check=False) for r, sim in zip(recs, after_runs)]
    runtime["compare"] = time.perf_counter() - t0
    runtime["total"] = time.perf_counter() - t_start
    return Identification(
        rig=out_rig, start=start, mode=mode, keys=keys, values=values,
        start_values={k: float(v) for k, v in zip(keys, coords.start)},
        stage1_values={k: (float(s1_vals[i]) if k in stage1_keys else None) for i, k in enumerate(keys)},
        intervals=u["intervals"], std=u["std"], correlation=u["correlation"],
        flags=extra["notes"] + not_improved_flags(kept, costs) + separability_flags(
            keys, values, u["intervals"], u["correlation"], u["status"]),
        before=before, after=after, generic_start=generic, weights=weights, integrator=options.method.name.lower(),
        n_eff=float(u["n_eff"]), rho1=float(u["rho1"]), nfev=nfev, runtime_s=runtime, status=u["status"],
        costs=costs, kept=kept, checks=found + [c for a in after for c in a.checks], field_input=extra["field"],
        law=extra["law"], runs=runs)


__all__ = ["Comparison", "Identification", "as_records", "identify", "key_status", "separability_flags",
           "uncertainty"]
