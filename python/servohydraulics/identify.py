"""Deprecated alias (removed in 0.3.0): the paper-era fits moved to
:mod:`servohydraulics.identification.paper`, the AR(1) helpers to
:mod:`servohydraulics.identification.stats`, the DFT-ratio frequency response to
:func:`servohydraulics.identification.frf.dft_ratio`.  ``sh.identify`` is the function
:func:`servohydraulics.identification.identify` (until this alias is imported: importing a
submodule binds the package attribute of its name to it)."""

from __future__ import annotations

import warnings as _warnings

from .identification._compat import fourier_ratio, frequency_response  # noqa: F401
from .identification.paper import *  # noqa: F403 (the paper-era fits under their old module)
from .identification.stats import ar1_coefficient, ar1_effective_n, lag1_autocorrelation  # noqa: F401

_warnings.warn("servohydraulics.identify (the module) is deprecated and will be removed in 0.3.0; use "
               "servohydraulics.identification (importing this module rebinds sh.identify to it; the function is "
               "servohydraulics.identification.identify)", DeprecationWarning, stacklevel=2)
