"""The DFT-ratio helpers of the deprecated ``servohydraulics.identify`` and ``signals``
modules, as they returned them (tuples); both are :func:`.frf.dft_ratio` (removed in 0.3.0)."""

from __future__ import annotations

import numpy as np

from ..timegrid import uniform_dt
from .frf import dft_ratio


def frequency_response(time, command, response, min_level: float = 0.05):
    """(f [Hz], H, excited mask) of :func:`~servohydraulics.identification.frf.dft_ratio`."""
    est = dft_ratio(command, response, uniform_dt(time, "invalid time", min_rows=10), min_level)
    return est.frequency, est.response, est.excited


def fourier_ratio(output, reference, dt: float):
    """(f [Hz], |Y/U|) of :func:`~servohydraulics.identification.frf.dft_ratio` without the at-rest start."""
    y = np.asarray(output, dtype=float)
    est = dft_ratio(np.asarray(reference, dtype=float)[: y.size], y, dt, min_level=0.0, from_rest=False)
    return est.frequency, np.abs(est.response)
