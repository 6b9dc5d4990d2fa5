"""The time stage's simulations: the records cut into segments that run on parallel threads, and
a cache of the runs already made.

A simulation-error fit simulates the same records hundreds of times, each run on one thread of the
core (which releases the GIL while it simulates).  :class:`Target` cuts each record into
``workers`` segments, each simulated from rest at the measured displacement ``warmup`` seconds
before its first compared sample (the warm-up's samples are simulated and dropped), so that the
segments of one run, and the runs of a Jacobian's columns, keep every thread busy.  The warm-up
(:func:`warmup_seconds`) is ``WARMUP_DECAYS`` time constants of the slowest decaying mode of the
loop linearised at the record's start (at least ``MIN_WARMUP``): the start's transient has decayed
to e^-15 of its size by the first compared sample, so a segmented run agrees with the whole
record's run to within the integrator's tolerance (the UTFSM chirp: 5e-7 of the displacement's and
7e-5 of the force's standard deviation at worst, the difference between two runs of the pair at
rtol 1e-6).  :meth:`Target.agrees` measures that agreement against whole runs; ``sh.identify``
checks it on the start and on the result and falls back where it fails (``AGREEMENT``).

The residual of a run (``w (sim - measured) / std(measured)`` per record and channel) is cached by
the rig (its ``repr``: every field), so that the stages' comparisons and the final Jacobian's
centre reuse the runs of the fit (``CACHE_SIZE`` runs kept).
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from ..response import Response, SimulationError
from ..rig import Rig
from .run import controller_ratio, initial_displacement, record_rig, simulate_command

FAILED = 10.0  #: normalised residual of a failed simulation
#: the warm-up: this many time constants of the slowest decaying linear mode, at least MIN_WARMUP [s]
WARMUP_DECAYS, MIN_WARMUP = 15.0, 0.5
#: a record is cut into segments only if each is at least this many warm-ups long
MIN_SEGMENT_WARMUPS = 4.0
#: a target's run must agree with the whole run of the error-controlled pair to these fractions of
#: each channel's standard deviation, largest difference and rms: far below any misfit a fit
#: resolves (a 0.01 % NRMSE)
AGREEMENT, AGREEMENT_RMS = 1e-3, 1e-4
CACHE_SIZE = 8


@dataclass(frozen=True)
class Segment:
    """One run of a piece of a record: simulated from sample ``start`` (from rest at the measured
    displacement there), compared from ``keep`` to ``stop`` (exclusive)."""

    start: int
    keep: int
    stop: int


def warmup_seconds(rig: Rig, mode: str, x0: float) -> float | None:
    """The warm-up [s] that lets a run started from rest mid-record forget its start:
    ``WARMUP_DECAYS`` / (the slowest decay rate of the loop linearised at ``x0``), at least
    ``MIN_WARMUP``; None when the linearisation fails or has a mode that does not decay (modes of
    zero rate, states nothing reads such as a damper's internal displacement without its spring,
    are left out)."""
    from ..linear_plant import friction_off, plant_matrices

    try:
        lam = np.linalg.eigvals(np.asarray(plant_matrices(friction_off(rig), mode, x0=x0).A, dtype=float))
    except (ValueError, np.linalg.LinAlgError):
        return None
    big = float(np.max(np.abs(lam))) if lam.size else 0.0
    lam = lam[np.abs(lam) > 1e-9 * big]
    if lam.size == 0 or not np.all(np.isfinite(lam)):
        return None
    rate = float(np.min(-lam.real))
    if rate <= 0.0:
        return None
    return max(MIN_WARMUP, WARMUP_DECAYS / rate)


def whole(record: Response) -> list[Segment]:
    """The record as one run."""
    return [Segment(0, 0, record.time.size)]


def split(record: Response, warmup: float | None, parts: int, dt: float | None = None) -> list[Segment]:
    """The record in ``parts`` segments of equal length, each with ``warmup`` [s] of run before it;
    the whole record when the warm-up is None, a segment would be shorter than
    ``MIN_SEGMENT_WARMUPS`` warm-ups, or the controller runs slower than the record (its samples
    must align with the whole run's)."""
    n = record.time.size
    if warmup is None or parts <= 1 or not controller_ratio(record.dt, n, dt)[1]:
        return whole(record)
    warm = int(math.ceil(warmup / record.dt))
    parts = min(parts, int(n // (MIN_SEGMENT_WARMUPS * warm)))
    if parts <= 1:
        return whole(record)
    edges = np.linspace(0, n, parts + 1).round().astype(int)
    return [Segment(max(0, int(a) - warm), int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]


class Target:
    """The records' measured channels over the compared samples of their segments, and their runs
    (see the module docstring); ``residual`` / ``residuals`` evaluate rigs, the latter several at
    once over the threads.  Use as a context manager (or call ``close``) to end the threads."""

    def __init__(self, records: list[Response], mode: str, channels: tuple[str, ...], options,
                 dt: float | None, segments: list[list[Segment]], workers: int = 1) -> None:
        self.records, self.mode, self.channels, self.options, self.dt = records, mode, tuple(channels), options, dt
        self.segments = segments
        self.workers = max(1, int(workers))
        idx = [np.concatenate([np.arange(s.keep, s.stop) for s in segs]) for segs in segments]
        self.measured = [{ch: np.asarray(r.channels[ch], dtype=float)[i] for ch in self.channels}
                         for r, i in zip(records, idx)]
        self.std = [{ch: float(np.std(np.asarray(r.channels[ch], dtype=float))) for ch in self.channels}
                    for r in records]
        #: lengths of the (record, channel) series the residual stacks, in order
        self.lengths = [int(i.size) for i in idx for _ in self.channels]
        self.size = int(sum(self.lengths))
        self.runs = 0  #: segment runs made (cache hits not counted)
        self._pool: ThreadPoolExecutor | None = None
        self._cache: OrderedDict = OrderedDict()
        self._lock = threading.Lock()

    @classmethod
    def build(cls, records: list[Response], mode: str, channels, options, dt: float | None, rig: Rig,
              workers: int) -> Target:
        """The whole records, each in ``workers`` segments with the warm-up of ``rig`` linearised at
        the record's start (``split``)."""
        segs = [split(r, warmup_seconds(record_rig(rig, r), mode, initial_displacement(r)), workers, dt)
                for r in records]
        return cls(records, mode, channels, options, dt, segs, workers)

    def whole_runs(self) -> Target:
        """The same records as one run each (the fallback when segments disagree)."""
        return Target(self.records, self.mode, self.channels, self.options, self.dt,
                      [whole(r) for r in self.records], self.workers)

    @property
    def segmented(self) -> bool:
        return any(len(s) > 1 or s[0].start > 0 or s[0].stop < r.time.size
                   for s, r in zip(self.segments, self.records))

    def __enter__(self) -> Target:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None

    def _map(self, fn, items: list) -> list:
        if self.workers <= 1 or len(items) <= 1:
            return [fn(i) for i in items]
        if self._pool is None:
            self._pool = ThreadPoolExecutor(max_workers=self.workers)
        return list(self._pool.map(fn, items))

    def _run(self, rig: Rig, i: int, seg: Segment) -> dict | None:
        """One segment of record i through the rig: its channels over the compared samples."""
        rec = self.records[i]
        u = np.asarray(rec.command, dtype=float)
        x0 = initial_displacement(rec) if seg.start == 0 else float(np.asarray(rec.displacement)[seg.start])
        try:
            sim = simulate_command(record_rig(rig, rec), self.mode, u[seg.start:seg.stop], rec.dt, x0, self.options,
                                   self.dt)
        except (SimulationError, ValueError):
            return None
        cut = seg.keep - seg.start
        out = {ch: np.asarray(sim.channels[ch], dtype=float)[cut:] for ch in self.channels}
        return out if all(np.all(np.isfinite(v)) for v in out.values()) else None

    def simulations(self, rigs: list[Rig | None]) -> list[list[dict | None]]:
        """Per rig (None: no run) and record, the simulated channels over the compared samples
        (None where a segment failed); the segments of all the rigs on the threads together."""
        tasks = [(k, i, s) for k, rig in enumerate(rigs) if rig is not None
                 for i, segs in enumerate(self.segments) for s in range(len(segs))]
        parts = self._map(lambda t: self._run(rigs[t[0]], t[1], self.segments[t[1]][t[2]]), tasks)
        self.runs += len(tasks)
        got: dict = {}
        for (k, i, _), p in zip(tasks, parts):
            got.setdefault((k, i), []).append(p)
        out = []
        for k, rig in enumerate(rigs):
            row = []
            for i in range(len(self.records)):
                ps = got.get((k, i))
                row.append(None if rig is None or ps is None or any(p is None for p in ps) else
                           {ch: np.concatenate([p[ch] for p in ps]) for ch in self.channels})
            out.append(row)
        return out

    def _unweighted(self, sims: list[dict | None]) -> dict[str, list[np.ndarray]]:
        return {ch: [np.full(m[ch].size, FAILED) if s is None else (s[ch] - m[ch]) / sd[ch]
                     for s, m, sd in zip(sims, self.measured, self.std)] for ch in self.channels}

    def lengths_of(self, channels: tuple[str, ...] | None = None) -> list[int]:
        """Lengths of the (record, channel) series of ``residuals(..., channels)``, in order."""
        chans = self.channels if channels is None else tuple(channels)
        return [n for n, (i, ch) in zip(self.lengths, ((i, c) for i in range(len(self.records))
                                                        for c in self.channels)) if ch in chans]

    def residuals(self, rigs: list[Rig | None], weights: dict | None = None,
                  channels: tuple[str, ...] | None = None) -> list[np.ndarray]:
        """``w_ch (sim - measured) / std(measured)`` of every record and channel (record-major; the
        ``channels`` given, default all) for each rig (None: an invalid rig, every entry ``FAILED``),
        from the cache where the rig was run before."""
        chans = self.channels if channels is None else tuple(channels)
        keys = [None if r is None else repr(r) for r in rigs]
        with self._lock:
            have = {k: self._cache[k] for k in keys if k is not None and k in self._cache}
        todo = list(dict.fromkeys(k for k in keys if k is not None and k not in have))
        if todo:
            first = {k: r for k, r in zip(keys, rigs) if k in todo}
            sims = self.simulations([first[k] for k in todo])
            with self._lock:
                for k, s in zip(todo, sims):
                    have[k] = self._cache[k] = self._unweighted(s)
                    while len(self._cache) > CACHE_SIZE:
                        self._cache.popitem(last=False)
        out = []
        w = {ch: 1.0 if weights is None else weights[ch] for ch in chans}
        for k in keys:
            if k is None:
                out.append(np.full(sum(self.lengths_of(chans)), FAILED))
                continue
            out.append(self._weighted(have[k], w, chans))
        return out

    def completed(self, rigs: list[Rig], weights: dict | None = None) -> list[np.ndarray | None]:
        """``residuals`` of the rigs over every channel, run together (not cached), None for a rig whose
        run failed on a segment instead of its ``FAILED`` entries."""
        w = {ch: 1.0 if weights is None else weights[ch] for ch in self.channels}
        return [None if any(s is None for s in row) else self._weighted(self._unweighted(row), w, self.channels)
                for row in self.simulations(rigs)]

    def _weighted(self, e: dict, w: dict, chans: tuple[str, ...]) -> np.ndarray:
        return np.concatenate([w[ch] * e[ch][i] for i in range(len(self.records)) for ch in chans])

    def residual(self, rig: Rig | None, weights: dict | None = None,
                 channels: tuple[str, ...] | None = None) -> np.ndarray:
        return self.residuals([rig], weights, channels)[0]

    def of(self, sims: list[Response], weights: dict | None = None) -> np.ndarray:
        """The residual (as ``residuals``) of the whole runs ``sims`` (one per record,
        ``run.simulate_record``) over this target's compared samples."""
        ref = []
        w = {ch: 1.0 if weights is None else weights[ch] for ch in self.channels}
        for segs, sim, meas, sd in zip(self.segments, sims, self.measured, self.std):
            ix = np.concatenate([np.arange(s.keep, s.stop) for s in segs])
            ref += [w[ch] * (np.asarray(sim.channels[ch], dtype=float)[ix] - meas[ch]) / sd[ch]
                    for ch in self.channels]
        return np.concatenate(ref)

    def gap(self, rig: Rig, sims: list[Response]) -> tuple[float, float]:
        """How far this target's run of ``rig`` is from the whole runs ``sims`` (one per record,
        ``run.simulate_record``, e.g. by the error-controlled pair): (the largest difference, the
        largest rms difference of a (record, channel) series), each as a fraction of the channel's
        standard deviation; (inf, inf) when a run failed."""
        d = self.residual(rig) - self.of(sims)
        parts = np.split(d, np.cumsum(self.lengths)[:-1])
        worst, rms = float(np.max(np.abs(d))), max(float(np.sqrt(np.mean(p ** 2))) for p in parts)
        return (worst, rms) if math.isfinite(worst) and math.isfinite(rms) else (math.inf, math.inf)

    def agrees(self, rig: Rig, sims: list[Response]) -> bool:
        """Whether this target's run of ``rig`` stands for the whole runs ``sims``: its ``gap`` within
        ``AGREEMENT`` (largest) and ``AGREEMENT_RMS`` (rms)."""
        worst, rms = self.gap(rig, sims)
        return worst <= AGREEMENT and rms <= AGREEMENT_RMS


__all__ = ["AGREEMENT", "AGREEMENT_RMS", "FAILED", "Segment", "Target", "split", "warmup_seconds", "whole"]
