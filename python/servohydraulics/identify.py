"""Deprecated alias (removed in 0.3.0): the paper-era fits moved to
:mod:`servohydraulics.identification.paper`, the AR(1) helpers to
:mod:`servohydraulics.identification.stats`, the DFT-ratio frequency response to
:func:`servohydraulics.identification.frf.dft_ratio`.  ``sh.identify`` is the function
:func:`servohydraulics.identification.identify`."""

from __future__ import annotations

import warnings as _warnings

import numpy as _np

from .identification.frf import dft_ratio as _dft_ratio
from .identification.paper import *  # noqa: F403 (the paper-era fits under their old module)
from .identification.stats import ar1_coefficient, ar1_effective_n, lag1_autocorrelation  # noqa: F401
from .response import uniform_dt as _uniform_dt

_warnings.warn("servohydraulics.identify (the module) is deprecated and will be removed in 0.3.0; use "
               "servohydraulics.identification (sh.identify is the function identification.identify)",
               DeprecationWarning, stacklevel=2)


def frequency_response(time, command, response, min_level: float = 0.05):
    """(f [Hz], H, excited mask) of :func:`~servohydraulics.identification.frf.dft_ratio`."""
    est = _dft_ratio(command, response, _uniform_dt(time, "invalid time", min_rows=10), min_level)
    return est.frequency, est.response, est.excited


def fourier_ratio(output, reference, dt: float):
    """(f [Hz], |Y/U|) of :func:`~servohydraulics.identification.frf.dft_ratio` without the at-rest start."""
    y = _np.asarray(output, dtype=float)
    est = _dft_ratio(_np.asarray(reference, dtype=float)[: y.size], y, dt, min_level=0.0, from_rest=False)
    return est.frequency, _np.abs(est.response)
