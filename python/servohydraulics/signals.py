"""Deprecated alias: the signal analysis moved to :mod:`servohydraulics.identification`
(``frf.dft_ratio``, ``identify_free_vibration``, ``FreeVibration``); this module
will be removed in 0.3.0."""

import warnings as _warnings

_warnings.warn("signals is deprecated and will be removed in 0.3.0; import servohydraulics.identification",
               DeprecationWarning, stacklevel=2)

from .identification._compat import fourier_ratio  # noqa: E402, F401
from .identification.paper import FreeVibration, identify_free_vibration  # noqa: E402, F401
