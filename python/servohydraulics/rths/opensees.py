"""A numerical substructure taken from an OpenSeesPy model, stepped once per
controller sample inside the RTHS loop (the role OpenFresco plays between a
controller and OpenSees, without the middleware).

    def frame(ops):                          # any OpenSeesPy model: nodes, masses, elements, damping
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        ...
    num = OpenSeesSubstructure(frame, dofs=[(1, 1), (2, 1), (3, 1)], ground=[1000.0] * 3, interface=0)
    trial = rths.run_trial(case, rec, "sample", numerical=num)

Each sample the adapter sets the nodal loads -g_i a_g - gamma_i f_in on the
listed DOFs (``ground`` g: the ground-load vector, e.g. the reference masses
M_r iota of the benchmark; f_in: the delayed measured specimen force, on the
``interface`` DOF) through OpenSees parameters, then calls ``analyze(1, h)``.
Schemes: ``"central_difference"`` (OpenSees ``CentralDifference``, explicit,
loads at t_k; nonlinear elements enter through their resisting forces) and
``"newmark"`` (average acceleration, implicit, Newton iterations, loads at
t_k + h).  OpenSeesPy keeps one model per process: one adapter at a time, and
``reset()`` (called by the loop at the start of every run) rebuilds the model
from ``model``.  Velocity and acceleration are OpenSees' (for the central
difference, those of the previous sample: the scheme computes them one step
behind); only the predictive compensators read them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Callable

import numpy as np

from .data import DT

__all__ = ["OpenSeesSubstructure", "spring_model"]

_TS, _PATTERN, _PARAM0 = 1_900_001, 1_900_001, 1_900_001  # tags clear of a user's model
SCHEMES = ("central_difference", "newmark")


def _opensees():
    try:
        import openseespy.opensees as ops
    except ImportError as e:  # pragma: no cover - openseespy is a dependency of the venv
        raise ImportError("OpenSeesSubstructure needs the PyPI package openseespy "
                          "(pip install servohydraulics[opensees])") from e
    return ops


class OpenSeesSubstructure:
    """An OpenSeesPy model as the RTHS loop's numerical substructure.

    Args:
        model: ``model(ops)`` defines the model on a wiped domain (``ops.model``, nodes,
            ``fix``, ``mass``, elements, ``rayleigh``); no analysis objects or load patterns.
        dofs: the (node, dof) read back as the substructure's displacements, in order.
        ground: g_i of those DOFs [kg]: the load -g_i a_g.
        interface: index into ``dofs`` of the DOF the specimen force acts on (load -f_in).
        h: the controller sample [s].
        scheme: ``"central_difference"`` or ``"newmark"``.
    """

    def __init__(self, model: Callable[[Any], None], dofs: Sequence[tuple[int, int]], ground: Sequence[float],
                 interface: int = 0, h: float = DT, scheme: str = "central_difference"):
        self.dofs = [(int(n), int(d)) for n, d in dofs]
        self.ground = [float(g) for g in ground]
        if not self.dofs:
            raise ValueError("invalid dofs = []: give the (node, dof) to read back")
        if len(self.ground) != len(self.dofs) or not all(math.isfinite(g) for g in self.ground):
            raise ValueError(f"invalid ground = {list(ground)!r}: one finite value per DOF ({len(self.dofs)})")
        if not (isinstance(interface, int) and 0 <= interface < len(self.dofs)):
            raise ValueError(f"invalid interface = {interface!r}: an index into dofs (0 .. {len(self.dofs) - 1})")
        if not (isinstance(h, (int, float)) and math.isfinite(h) and h > 0):
            raise ValueError(f"invalid h = {h!r}: finite and > 0 [s]")
        if scheme not in SCHEMES:
            raise ValueError(f"invalid scheme = {scheme!r}: expected one of {list(SCHEMES)}")
        self.model, self.interface_dof, self.h, self.scheme = model, interface, float(h), scheme
        self.size = len(self.dofs)
        self.ops = _opensees()
        self.reset()

    # --- the protocol of the loop's numerical substructure (servohydraulics._core.rths.PythonSubstructure)
    def reset(self) -> None:
        """Rebuild the model at rest at t = 0, with the adapter's load pattern and analysis."""
        ops = self.ops
        ops.wipe()
        self.model(ops)
        ops.timeSeries("Constant", _TS)
        ops.pattern("Plain", _PATTERN, _TS)
        for node in dict.fromkeys(n for n, _ in self.dofs):
            ops.load(node, *([0.0] * ops.getNDF(node)[0]))
        for i, (node, dof) in enumerate(self.dofs):
            ops.parameter(_PARAM0 + i, "loadPattern", _PATTERN, "loadAtNode", node, dof)
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        if self.scheme == "central_difference":
            ops.algorithm("Linear")
            ops.integrator("CentralDifference")
        else:
            ops.test("NormDispIncr", 1e-12, 50)
            ops.algorithm("Newton")
            ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")

    def step(self, ag0: float, ag_mid: float, ag1: float, f_in: float) -> None:
        """One sample: the loads -g a_g - gamma f_in (a_g at t_k for the central difference,
        at t_k + h for Newmark), then ``analyze(1, h)``."""
        ops = self.ops
        ag = ag0 if self.scheme == "central_difference" else ag1
        for i, g in enumerate(self.ground):
            ops.updateParameter(_PARAM0 + i, -g * ag - (f_in if i == self.interface_dof else 0.0))
        t = ops.getTime()
        if ops.analyze(1, self.h) != 0:
            raise RuntimeError(f"OpenSees analyze failed at t = {t:.6g} s (scheme {self.scheme})")

    def displacements(self) -> list[float]:
        return [self.ops.nodeDisp(n, d) for n, d in self.dofs]

    def interface_velocity(self) -> float:
        n, d = self.dofs[self.interface_dof]
        return self.ops.nodeVel(n, d)

    def interface_acceleration(self, ag: float, f_in: float) -> float:
        n, d = self.dofs[self.interface_dof]
        return self.ops.nodeAccel(n, d)


def spring_model(M: np.ndarray, K: np.ndarray, rayleigh: tuple[float, float] = (0.0, 0.0),
                 yielding: dict[tuple[int, int], tuple[float, float]] | None = None) -> Callable[[Any], None]:
    """A 1-D OpenSees model (``model(ops)`` for OpenSeesSubstructure) with the lumped masses
    diag(M) [kg] and the stiffness K [N/m]: node i+1 carries M[i, i] and DOF i; a zeroLength
    spring of -K[i, j] joins nodes i+1 and j+1, one of the row sum of K joins node i+1 to the
    fixed node 0 (none where it vanishes, as in a shear building), so that the assembled
    stiffness is K.  ``rayleigh`` = (a, b): C = a M + b K
    (initial stiffness; ``-doRayleigh`` on every spring).  ``yielding``: {(p, q): (F_y [N], b [-])}
    makes the spring between nodes p and q (0 = ground) a bilinear Steel01 of the same initial
    stiffness, yield force F_y and hardening ratio b."""
    M, K = np.asarray(M, dtype=float), np.asarray(K, dtype=float)
    n = M.shape[0]
    if M.shape != (n, n) or K.shape != (n, n) or not (np.all(np.isfinite(M)) and np.all(np.isfinite(K))):
        raise ValueError(f"invalid M, K shapes = {M.shape}, {K.shape}: square, the same size, finite")
    if np.any(np.diag(M) <= 0):
        raise ValueError(f"invalid M diagonal = {np.diag(M).tolist()}: lumped masses > 0")
    tiny = 1e-12 * float(np.max(np.abs(K)))  # row sums of a shear building's K vanish but for round-off
    springs = [(0, i + 1, float(K[i].sum())) for i in range(n) if abs(K[i].sum()) > tiny]
    springs += [(i + 1, j + 1, float(-K[i, j])) for i in range(n) for j in range(i + 1, n) if K[i, j] != 0.0]
    yielding = dict(yielding or {})
    known = {(p, q) for p, q, _ in springs}
    for key, (fy, b) in yielding.items():
        if key not in known or not (math.isfinite(fy) and fy > 0 and math.isfinite(b) and 0 <= b < 1):
            raise ValueError(f"invalid yielding[{key}] = {(fy, b)}: a spring (p, q) of the model, F_y > 0, 0 <= b < 1")
    a, b = (float(v) for v in rayleigh)

    def build(ops) -> None:
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        ops.node(0, 0.0)
        ops.fix(0, 1)
        for i in range(n):
            ops.node(i + 1, 0.0)
            ops.mass(i + 1, float(M[i, i]))
        for tag, (p, q, k) in enumerate(springs, start=1):
            if (p, q) in yielding:
                fy, hard = yielding[(p, q)]
                ops.uniaxialMaterial("Steel01", tag, fy, k, hard)
            else:
                ops.uniaxialMaterial("Elastic", tag, k)
            ops.element("zeroLength", tag, p, q, "-mat", tag, "-dir", 1, "-doRayleigh", 1)
        ops.rayleigh(a, 0.0, b, 0.0)
    return build
