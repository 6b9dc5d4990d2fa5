"""Deprecated alias: the signal analysis moved to :mod:`servohydraulics.identify`
(``fourier_ratio``, ``identify_free_vibration``, ``FreeVibration``); this module
will be removed in the next release."""

from .identify import FreeVibration, fourier_ratio, identify_free_vibration  # noqa: F401
