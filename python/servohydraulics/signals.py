"""Deprecated alias: the signal analysis moved to :mod:`servohydraulics.identify`
(``fourier_ratio``, ``identify_free_vibration``, ``FreeVibration``); this module
will be removed in the next release."""

import warnings as _warnings

_warnings.warn("signals is deprecated; import servohydraulics.identify", DeprecationWarning, stacklevel=2)

from .identify import FreeVibration, fourier_ratio, identify_free_vibration  # noqa: F401
