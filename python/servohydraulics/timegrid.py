"""The sample-time grid of every record: the core's default controller sample time,
uniform time axes (``time_axis``) and the check that a record's axis is one (``uniform_dt``).

NumPy only: the plant's simulation imports it, so ``import servohydraulics`` loads
no SciPy (the excitations that need ``scipy.signal`` live in ``excitations``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from . import _core

DT = _core.EftConfig().dt  #: the paper's controller sample time (2 kHz), the core's default [s]

#: Longest time axis made here: 50 M samples (7 h at 2 kHz, 400 MB per channel).
MAX_SAMPLES = 50_000_000


def positive(name: str, value: float) -> float:
    """``value`` as a float; ValueError naming ``name`` unless it is a finite number > 0."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"invalid {name} = {value!r}: must be finite and > 0")
    return float(value)


def time_axis(duration: float, dt: float = DT) -> np.ndarray:
    """t_k = k dt for k = 0..round(duration/dt) [s] (at most MAX_SAMPLES samples)."""
    positive("duration", duration)
    positive("dt", dt)
    n = duration / dt
    if not n < MAX_SAMPLES:
        raise ValueError(f"invalid duration = {duration!r} s at dt = {dt!r} s: {n:.3g} samples, more than "
                         f"the {MAX_SAMPLES:,} allowed")
    return np.arange(int(round(n)) + 1) * dt


def uniform_dt(time: ArrayLike, where: str = "time", min_rows: int = 2) -> float:
    """The sample time [s] of a uniformly sampled, increasing time axis; errors name ``where``."""
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < min_rows:
        raise ValueError(f"{where}: a record needs at least {min_rows} rows in a 1-D time axis, got shape {t.shape}")
    d = np.diff(t)
    if np.any(d <= 0):
        i = int(np.flatnonzero(d <= 0)[0])
        raise ValueError(f"{where}: time must be increasing; time[{i + 1}] = {t[i + 1]} <= time[{i}] = {t[i]}")
    dt = (t[-1] - t[0]) / (t.size - 1)
    worst = int(np.argmax(np.abs(d - dt)))
    if abs(d[worst] - dt) > 1e-6 * dt + 1e-12:
        raise ValueError(f"{where}: time must be uniform; step {worst} is {d[worst]:.9g} s, "
                         f"the mean step is {dt:.9g} s")
    return float(dt)
