"""The plant's linearisation as plain matrices, without python-control.

:func:`plant_matrices` is the one place the C++ model's tangent linearisation
(``_core.linearize_dynamics`` about ``Dynamics.operating_point``) is cut down to
the active states and the requested outputs.  ``sh.analysis.linearize`` wraps its
result in a ``control.StateSpace`` (and puts compensators around it); the fits
that linearise hundreds of times (``sh.identify``'s frequency stage, the
segments' warm-up, the diagnosis' stability bounds) call it directly: the same
matrices, without importing python-control (about a second, as it imports
pyplot) or building a ``StateSpace`` per call.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import _core
from .rig import Rig, copy_rig
from .simulate import MODES

#: the plant's output channels (the core's channel table but time), in the order of the core's C rows
OUTPUTS = tuple(n for n, _ in _core.PLANT_CHANNELS if n != "time")


@dataclass(frozen=True)
class PlantMatrices:
    """x' = A x + B u, y = C x + D u about the operating point, the active states only."""

    A: np.ndarray
    B: np.ndarray  #: n x 1
    C: np.ndarray  #: outputs x n
    D: np.ndarray  #: outputs x 1
    states: tuple[str, ...]
    outputs: tuple[str, ...]


def friction_off(rig: Rig) -> Rig:
    """A copy of the rig with the Coulomb friction dropped (the linear analysis' default treatment:
    the tanh law's tangent at v = 0 describes a structure stuck in static friction)."""
    r = copy_rig(rig)
    r.effects.coulomb_friction = False
    return r


def check_arguments(mode: str, outputs: Sequence[str], x0: float) -> tuple[str, ...]:
    """The outputs as a tuple; ValueError naming the argument for an unknown mode or output, no output, or a
    non-finite x0 [m]."""
    if mode not in MODES:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    outs = tuple(outputs)
    for o in outs:
        if o not in OUTPUTS:
            raise ValueError(f"invalid output = {o!r}: expected one of {list(OUTPUTS)}")
    if not outs:
        raise ValueError("invalid outputs = (): name at least one output channel")
    if not math.isfinite(x0):
        raise ValueError(f"invalid x0 = {x0!r}: must be finite [m]")
    return outs


def plant_matrices(rig: Rig, mode: str = "displacement", x0: float = 0.0, u0: float | None = None,
                   outputs: Sequence[str] = ("displacement",)) -> PlantMatrices:
    """The rig (as given: see :func:`friction_off`) linearised about its static equilibrium at x0 [m]
    under the held command u0 (default: the command that holds x0), the inactive states dropped.
    ValueError naming the argument for an unknown mode or output, or a non-finite x0."""
    outs = check_arguments(mode, outputs, x0)
    dyn = _core.Dynamics(rig, MODES[mode])
    y0, u_hold = dyn.operating_point(float(x0))
    lm = _core.linearize_dynamics(dyn, y0, u_hold if u0 is None else float(u0))
    keep = np.flatnonzero(np.asarray(lm.active, dtype=bool))
    rows = [OUTPUTS.index(o) for o in outs]
    names = [s[0] for s in dyn.states]  # the base states, then the switched-on elements' (specimens, loop delay)
    return PlantMatrices(A=np.asarray(lm.A)[np.ix_(keep, keep)], B=np.asarray(lm.B).reshape(-1, 1)[keep],
                         C=np.asarray(lm.C)[np.ix_(rows, keep)], D=np.asarray(lm.D).reshape(-1, 1)[rows],
                         states=tuple(names[i] for i in keep), outputs=outs)


__all__ = ["OUTPUTS", "PlantMatrices", "check_arguments", "friction_off", "plant_matrices"]
