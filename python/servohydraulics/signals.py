"""Deprecated alias: the signal analysis moved to :mod:`servohydraulics.identification`
(``frf.dft_ratio``, ``identify_free_vibration``, ``FreeVibration``); this module
will be removed in 0.3.0."""

import warnings as _warnings

_warnings.warn("signals is deprecated and will be removed in 0.3.0; import servohydraulics.identification",
               DeprecationWarning, stacklevel=2)

with _warnings.catch_warnings():  # one warning for this alias, not a second one for the alias it reads
    _warnings.simplefilter("ignore", DeprecationWarning)
    from .identify import FreeVibration, fourier_ratio, identify_free_vibration  # noqa: F401
