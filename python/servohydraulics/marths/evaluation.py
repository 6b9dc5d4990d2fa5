"""J1-J10 of the maRTHS benchmark exactly as S5_Evaluation.m computes them (BENCHMARK.md section 8),
MATLAB's ``finddelay``, and the realizability rule.

Every series is the full logged record (k = 0 .. N-1, the zero padding included); ``std`` is the
sample standard deviation (N - 1); the criteria are ratios, so the loop's SI channels give the same
numbers as the model's mm.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

__all__ = ["J_COMPONENTS", "J_TITLES", "J_UNITS", "finddelay", "evaluate", "realizable", "SATURATION_LIMIT",
           "criteria_rows"]

#: The components of each criterion, in BENCHMARK.md's order.
J_COMPONENTS: dict[str, tuple[str, ...]] = {
    "J1": ("act1", "act2"), "J2": ("act1", "act2"), "J3": ("act1", "act2"), "J4": ("act1", "act2"),
    "J5": ("x", "theta"), "J6": ("x", "theta"), "J7": ("x", "theta"),
    "J8": ("x_2nd", "theta_2nd", "x_3rd", "theta_3rd"), "J9": ("x", "theta"),
    "J10": ("x_2nd", "theta_2nd", "x_3rd", "theta_3rd"),
}
#: Their names as S5 prints them (tracking control J1-J3, estimation J4-J6, global RTHS performance J7-J10).
J_TITLES = {
    "J1": "time delay (tracking)", "J2": "NRMS tracking error", "J3": "max peak tracking error",
    "J4": "time delay (estimation)", "J5": "NRMS estimation error vs the numerical substructure",
    "J6": "max peak estimation error vs the numerical substructure",
    "J7": "NRMS error of the interface vs the reference", "J8": "NRMS error of the upper stories vs the reference",
    "J9": "max peak error of the interface vs the reference",
    "J10": "max peak error of the upper stories vs the reference",
}
J_UNITS = {j: ("ms" if j in ("J1", "J4") else "%") for j in J_COMPONENTS}
#: The command voltage limit of the realizability check [V] (S1: sat_limit).
SATURATION_LIMIT = 3.8


def finddelay(x: np.ndarray, y: np.ndarray) -> int:
    """MATLAB's ``finddelay(x, y)`` for two vectors: the lag L (samples, positive when y lags x) maximising
    |sum_n y(n + L) x(n)| / sqrt(sum x^2 sum y^2) over all lags (the shorter vector padded with zeros, as
    ``xcorr``), the smallest |L| among equal maxima (equal to 1e-12, the FFT's round-off), the positive one on a
    tie of |L|; 0 when a signal is zero or the largest normalised correlation is below 1e-8 (finddelay's
    threshold for FFT round-off)."""
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.size == 0 or y.size == 0:
        raise ValueError(f"invalid signals: lengths {x.size} and {y.size}, expected nonzero lengths")
    n = max(x.size, y.size)
    x = np.concatenate([x, np.zeros(n - x.size)])
    y = np.concatenate([y, np.zeros(n - y.size)])
    nx, ny = float(np.dot(x, x)), float(np.dot(y, y))
    if nx == 0.0 or ny == 0.0:
        return 0
    from scipy import signal

    c = np.abs(signal.correlate(y, x, mode="full", method="fft")) / math.sqrt(nx * ny)
    lags = np.arange(-(n - 1), n)
    best = float(np.max(c))
    if best < 1e-8:
        return 0
    cand = lags[c >= best * (1.0 - 1e-12)]
    order = np.lexsort((-cand, np.abs(cand)))  # smallest |L|, then the positive one
    return int(cand[order[0]])


def _std(v: np.ndarray) -> float:
    return float(np.std(v, ddof=1))


def _peak(v: np.ndarray) -> float:
    return float(np.max(np.abs(v)))


def evaluate(ch: Mapping[str, np.ndarray], fs: float) -> dict[str, list[float]]:
    """J1 .. J10 (unrounded, BENCHMARK.md's units and component order) from a run's channels
    (``_core.marths.MARTHS_CHANNELS``) at the sample rate ``fs`` [Hz]."""
    def g(name: str) -> np.ndarray:
        return np.asarray(ch[name], dtype=float)

    t1, t2, m1, m2 = g("target_1"), g("target_2"), g("measured_1"), g("measured_2")
    xh, rh = g("x_estimate"), g("theta_estimate")
    xN, rN, xR, rR = g("x_numerical"), g("theta_numerical"), g("x_reference"), g("theta_reference")
    stories = [(g(f"{q}_story{s}_numerical"), g(f"{q}_story{s}_reference")) for s in (2, 3) for q in ("x", "theta")]
    nrms = lambda e, r: 100.0 * _std(e) / _std(r)  # noqa: E731
    peak = lambda e, r: 100.0 * _peak(e) / _peak(r)  # noqa: E731
    J1 = [finddelay(t1, m1) / fs * 1000.0, finddelay(t2, m2) / fs * 1000.0]
    return {
        "J1": J1,
        "J2": [nrms(m1 - t1, t1), nrms(m2 - t2, t2)],
        "J3": [peak(m1 - t1, t1), peak(m2 - t2, t2)],
        "J4": list(J1),  # identical to J1 in S5_Evaluation.m
        "J5": [nrms(xh - xN, xN), nrms(rh - rN, rN)],
        "J6": [peak(xh - xN, xN), peak(rh - rN, rN)],
        "J7": [nrms(xh - xR, xR), nrms(rh - rR, rR)],
        "J8": [nrms(n - r, r) for n, r in stories],
        "J9": [peak(xh - xR, xR), peak(rh - rR, rR)],
        "J10": [peak(n - r, r) for n, r in stories],
    }


def realizable(peak_volts, limit: float = SATURATION_LIMIT) -> bool:
    """S5's rule: the controller is NOT realizable when both actuators' peak command voltages exceed
    ``limit`` [V] (both, as coded)."""
    return not all(float(v) > limit for v in peak_volts)


def criteria_rows(J: Mapping[str, list[float]]) -> list[tuple[str, str, float, str]]:
    """(J, component, value, unit) rows in BENCHMARK.md's order."""
    return [(j, comp, float(v), J_UNITS[j]) for j in J_COMPONENTS for comp, v in zip(J_COMPONENTS[j], J[j])]
