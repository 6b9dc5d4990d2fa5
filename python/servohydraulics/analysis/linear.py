"""Linearisation of the C++ model into python-control objects, and the linear
compensator blocks of Fig 1 (phase leads, the ZOH delay).
Nonsmooth effects at an equilibrium
-----------------------------------
The nonlinear model has two points where the tangent linearisation is not the
small-signal model the paper analyses (Eqs 6-8):

* Coulomb friction ``F_c tanh(v / v_stick)`` has slope ``F_c / v_stick`` at
  ``v = 0`` (3.2e5 N s/m for the attached rig, 150 times ``c``): the tangent
  model describes a structure stuck in static friction.  ``linearize`` therefore
  takes ``friction="off"`` (default: F_c dropped), ``"equivalent"`` (Eq 8: F_c
  replaced by the energy-equivalent viscous damping ``4 F_c / (pi w X)`` of a
  harmonic motion of amplitude X at w, Jacobsen) or ``"tangent"`` (the raw
  Jacobian, stuck structure).
* The load-pressure factor of Eq (3) contains ``sgn(x_v)``; its derivative by p
  is multiplied by ``g(x_v)``, which vanishes at the null spool, so the Jacobian
  is continuous there (the C++ code uses sgn(0) = 0).  Away from null, the
  operating point's spool sign selects the branch: that is the valve's
  flow-pressure coefficient at that opening, and it is kept.
* Saturations (drive, spool end stops) are inactive at any equilibrium inside
  the travel; spring softening only matters for ``|x0| > x_contact``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import control as ct

from .. import _core
from ..linear_plant import OUTPUTS as LINEAR_OUTPUTS
from ..linear_plant import check_arguments, friction_off, plant_matrices
from ..rig import Rig, copy_rig
from .closed_form import equivalent_viscous_damping, velocity_feedback_gain

ALPHA = _core.RpsdConfig().alpha  #: constant of the paper's phase-lead networks (Table I), the core's default [-]
#: the plant's output channels (the core's channel table but time) -> SI unit, in the order of LinearModel.C's rows
OUTPUT_UNITS = {n: u for n, u in _core.PLANT_CHANNELS if n != "time"}
OUTPUTS = LINEAR_OUTPUTS  #: the same order as OUTPUT_UNITS (both the core's channel table but time)
STATE_UNITS = dict(_core.STATES)  #: the plant's states (the core's StateIndex order) -> SI unit
STATES = tuple(STATE_UNITS)
FRICTION_TREATMENTS = ("off", "equivalent", "tangent")


def phase_lead(T: float, alpha: float = ALPHA) -> ct.TransferFunction:
    """Phase-lead network (T s + 1)/(alpha T s + 1) of Fig 1 [-]; T [s]."""
    if not (math.isfinite(T) and T > 0):
        raise ValueError(f"invalid T = {T!r}: the lead time constant must be finite and > 0 [s]")
    if not (0 < alpha < 1):
        raise ValueError(f"invalid alpha = {alpha!r}: must be in (0, 1)")
    return ct.tf([T, 1.0], [alpha * T, 1.0])


def zoh_delay(dt: float, order: int = 3) -> ct.TransferFunction:
    """Half-sample delay of the zero-order hold of a controller at sample time dt [s] (Pade)."""
    num, den = ct.pade(dt / 2.0, order)
    return ct.tf(num, den)


@dataclass(frozen=True)
class Compensation:
    """Linear compensators put in the loop by :func:`linearize` (all times in s).

    amplitude_T: amplitude compensation lead (T s+1)/(alpha T s+1) on the
        command, Fig 1(b) (paper: 68 ms).
    velocity_feedback: EFT velocity-feedback compensation of Fig 1(a): the
        command gets ``A / (K_v K_s C_F G_p) * lead(velocity_feedback_T) * v``
        added, the linear inverse of the natural velocity feedback.
    velocity_feedback_T: phase lead of that path (paper: 5 ms); None: no lead.
    zoh_dt: controller sample time whose half-sample ZOH delay is put on the
        command (None: continuous).
    """

    amplitude_T: float | None = None
    velocity_feedback: bool = False
    velocity_feedback_T: float | None = None
    alpha: float = ALPHA
    zoh_dt: float | None = None


def linear_analysis_rig(rig: Rig, friction: str = "off", friction_amplitude: float = 0.0127,
                        friction_frequency: float | None = None) -> Rig:
    """Copy of the rig with the friction treated as in the linear analysis.

    friction: ``"off"`` (F_c dropped), ``"equivalent"`` (F_c replaced by
    ``c_eq = 4 F_c / (pi w X)``, Eq 8, at amplitude ``friction_amplitude`` [m]
    and ``friction_frequency`` [rad/s], default sqrt(k/m)), ``"tangent"``
    (unchanged).
    """
    if friction not in FRICTION_TREATMENTS:
        raise ValueError(f"invalid friction = {friction!r}: expected one of {list(FRICTION_TREATMENTS)}")
    if friction == "tangent":
        return copy_rig(rig)
    r = friction_off(rig)
    if friction == "equivalent" and rig.effects.coulomb_friction:
        r.c = r.c + equivalent_viscous_damping(rig, friction_amplitude, friction_frequency)
    return r


def linearize(rig: Rig, mode: str = "displacement", x0: float = 0.0, u0: float | None = None,
              outputs: Sequence[str] = ("displacement",), compensators: Compensation | None = None,
              friction: str = "off", friction_amplitude: float = 0.0127,
              friction_frequency: float | None = None) -> ct.StateSpace:
    """Linearises the nonlinear C++ model about its static equilibrium at x0.

    Args:
        rig: the rig (not modified).
        mode: ``"displacement"`` (input: command [m]), ``"force"`` (command [N])
            or ``"free"`` (ideal external force [N]).
        x0: operating displacement [m].
        u0: held command [m or N]; default: the command that holds x0 at rest
            (the core's ``Dynamics.operating_point``).
        outputs: channels among ``OUTPUTS`` (SI units, see ``OUTPUT_UNITS``).
        compensators: linear compensators in the loop (:class:`Compensation`).
        friction: treatment of the Coulomb friction (module docstring).
        friction_amplitude, friction_frequency: X [m] and w [rad/s] of the
            equivalent viscous damping (``friction="equivalent"``).

    Returns:
        ``control.StateSpace`` from input ``"u"`` to the named outputs, with the
        inactive states (pressure and spool in Free mode, the spool without
        valve dynamics) dropped, and the compensator states appended.
    """
    outs = list(check_arguments(mode, outputs, x0))
    comp = compensators or Compensation()
    r = linear_analysis_rig(rig, friction, friction_amplitude, friction_frequency)
    need = list(dict.fromkeys(outs + (["velocity"] if comp.velocity_feedback else [])))
    pm = plant_matrices(r, mode, x0, u0, need)
    plant = ct.ss(pm.A, pm.B, pm.C, pm.D, inputs=["u"], outputs=need, states=list(pm.states), name="plant")
    return _close_compensators(plant, r, mode, comp, outs)


def _close_compensators(plant: ct.StateSpace, rig: Rig, mode: str, comp: Compensation,
                        outs: list[str]) -> ct.StateSpace:
    """Puts the linear compensators around the plant (python-control interconnect)."""
    if comp.amplitude_T is None and not comp.velocity_feedback and comp.zoh_dt is None:
        return ct.ss(plant[[plant.output_labels.index(o) for o in outs], :]) if len(outs) < plant.noutputs \
            else plant
    blocks: list = [plant]
    signal = "u_cmd"
    chain: list[tuple[str, ct.TransferFunction]] = []
    if comp.amplitude_T is not None:
        chain.append(("amplitude_lead", phase_lead(comp.amplitude_T, comp.alpha)))
    if comp.zoh_dt is not None:
        chain.append(("zoh", zoh_delay(comp.zoh_dt)))
    for name, tf in chain:
        nxt = f"{name}_out"
        blocks.append(ct.ss(tf, inputs=[signal], outputs=[nxt], name=name))
        signal = nxt
    if comp.velocity_feedback:
        if mode != "force":
            raise ValueError(f"invalid compensators.velocity_feedback = True in mode = {mode!r}: "
                             "velocity-feedback compensation is the force-control (EFT) scheme")
        gain = velocity_feedback_gain(rig)  # [N per m/s]
        vf = ct.tf([gain], [1.0]) if comp.velocity_feedback_T is None else \
            gain * phase_lead(comp.velocity_feedback_T, comp.alpha)
        blocks.append(ct.ss(vf, inputs=["velocity"], outputs=["u_vfc"], name="velocity_feedback"))
        blocks.append(ct.summing_junction(inputs=[signal, "u_vfc"], output="u", name="sum"))
    else:
        blocks.append(ct.summing_junction(inputs=[signal], output="u", name="sum"))
    return ct.interconnect(blocks, inplist=["u_cmd"], outlist=outs, inputs=["u"], outputs=outs,
                           name="compensated")


__all__ = ["ALPHA", "Compensation", "FRICTION_TREATMENTS", "OUTPUTS", "OUTPUT_UNITS", "STATES", "STATE_UNITS",
           "linear_analysis_rig", "linearize", "phase_lead", "zoh_delay"]
