"""Deprecated alias of :mod:`servohydraulics.loops` (renamed to mirror the C++ loops.hpp).

Import ``servohydraulics.loops`` (or the top-level ``sh.run_eft``, ``sh.run_rpsd``,
``sh.run_tracking``) instead; this module will be removed in the next release.
"""

from __future__ import annotations

from .loops import (  # noqa: F401
    COMPENSATION,
    FORCE_MEASUREMENT,
    RESTORING_FORCE,
    SOLVERS,
    paper_numbers,
    run_eft,
    run_rpsd,
    run_tracking,
)
from .response import Response as MethodResult  # noqa: F401
from .response import SimulationError as TestMethodError  # noqa: F401

if __name__ == "__main__":
    for k, v in paper_numbers().items():
        print(f"{k}: {v}")
