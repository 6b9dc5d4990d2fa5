"""Deprecated alias of :mod:`servohydraulics.loops` (renamed to mirror the C++ loops.hpp).

Import ``servohydraulics.loops`` (or the top-level ``sh.run_eft``, ``sh.run_rpsd``,
``sh.run_tracking``) instead; this module will be removed in the next release.
"""

import warnings as _warnings

_warnings.warn("methods is deprecated; import servohydraulics.loops", DeprecationWarning, stacklevel=2)


from .loops import (  # noqa: F401, E402
    COMPENSATION,
    FORCE_MEASUREMENT,
    RESTORING_FORCE,
    SCHEMES,
    run_eft,
    run_rpsd,
    run_tracking,
)
from .response import Response as MethodResult  # noqa: F401, E402
from .response import SimulationError as TestMethodError  # noqa: F401, E402
