"""Linear model of the real-time pseudodynamic loop of Figs 7-10, in the
vocabulary of :func:`servohydraulics.run_rpsd` (``restoring_force`` and
``force_measurement``), with the core's ``RpsdConfig`` defaults (the paper's
68 ms, 11.2 ms, alpha, 7084 kg, 3.5 kN s/m, 0.5 ms).
"""

from __future__ import annotations

import control as ct

from .. import _core
from ..loops import FORCE_MEASUREMENT, RESTORING_FORCE
from ..rig import Rig, copy_rig
from .linear import ALPHA, linearize, phase_lead, zoh_delay

_DEFAULTS = _core.RpsdConfig()

#: The restoring forces of run_rpsd (Fig 7 and 9): (a) to (d).
RESTORING_FORCES = tuple(RESTORING_FORCE)


def fig10_variants(rig: Rig, physical_mass: float | None = None) -> dict[str, dict]:
    """The five restoring forces of Fig 10(b, c) as ``rpsd_loop`` keywords, by label:
    k x, the actuator force p A, p A - m a (damping kept), p A - m a - c v (piston
    ignored) and p A - (m + m_p) a - c v (exact).  ``physical_mass`` [kg] as in ``rpsd_loop``."""
    m = rig.m if physical_mass is None else float(physical_mass)
    pa = {"restoring_force": "measured_force_corrected", "force_measurement": "actuator_pressure"}
    return {
        "measured_displacement": {"restoring_force": "measured_displacement"},
        "measured_force": {"restoring_force": "measured_force", "force_measurement": "actuator_pressure"},
        "force_minus_inertia": {**pa, "subtract_mass": m, "subtract_damping": 0.0},
        "force_minus_inertia_damping": {**pa, "subtract_mass": m},
        "force_corrected": dict(pa),
    }


def _restoring_weights(r: Rig, restoring_force: str, force_measurement: str, k_m: float | None,
                       subtract_mass: float | None, subtract_damping: float | None) -> tuple[float, ...]:
    """f = w . (x_c, x, v, a, F_load_cell, p): the restoring force as run_rpsd computes it."""
    if restoring_force not in RESTORING_FORCE:
        raise ValueError(f"invalid restoring_force = {restoring_force!r}: expected one of {list(RESTORING_FORCES)}")
    if force_measurement not in FORCE_MEASUREMENT:
        raise ValueError(f"invalid force_measurement = {force_measurement!r}: expected one of "
                         f"{list(FORCE_MEASUREMENT)}")
    k = r.k if k_m is None else float(k_m)
    if restoring_force == "calculated_displacement":
        return (k, 0.0, 0.0, 0.0, 0.0, 0.0)
    if restoring_force == "measured_displacement":
        return (0.0, k, 0.0, 0.0, 0.0, 0.0)
    pressure = force_measurement == "actuator_pressure"
    F = (0.0, 0.0, 0.0, 0.0, 0.0, r.A) if pressure else (0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    if restoring_force == "measured_force":
        return F
    piston = r.m_p if pressure and r.effects.piston_mass else 0.0
    m_sub = r.m + piston if subtract_mass is None else float(subtract_mass)
    c_sub = r.c if subtract_damping is None else float(subtract_damping)
    return (0.0, 0.0, -c_sub, -m_sub, F[4], F[5])


def rpsd_loop(rig: Rig, m_m: float = _DEFAULTS.model.m_m, c_m: float = _DEFAULTS.model.c_m,
              restoring_force: str = "measured_displacement", amplitude_T: float | None = _DEFAULTS.amplitude_T,
              delay_T: float | None = _DEFAULTS.delay_T, alpha: float = ALPHA, physical_mass: float | None = None,
              zoh_dt: float | None = _DEFAULTS.dt, force_measurement: str = "load_cell", k_m: float | None = None,
              subtract_mass: float | None = None, subtract_damping: float | None = None) -> ct.StateSpace:
    """Linear model of the real-time pseudodynamic loop of Fig 7 (solver in continuous time).

    The solver of Eq (15), m_m a_c + c_m v_c + f = P, sends its displacement x_c
    through the amplitude lead (T_d, 68 ms) and the ZOH to the linearised
    displacement-controlled rig; the restoring force f comes back through the
    delay-compensation lead (T_ld, 11.2 ms).  ``amplitude_T``, ``delay_T`` or
    ``zoh_dt`` None (or 0): that block left out.

    ``restoring_force``, ``force_measurement``, ``k_m``, ``subtract_mass`` and
    ``subtract_damping`` mean what they mean in ``run_rpsd``: ``"calculated_displacement"``
    (f = k_m x_c), ``"measured_displacement"`` (f = k_m x), ``"measured_force"`` (the
    load cell, or p A with ``force_measurement="actuator_pressure"``) and
    ``"measured_force_corrected"`` (that force minus subtract_mass a + subtract_damping v,
    default the physical values).  :func:`fig10_variants` gives Fig 10's five.

    physical_mass: installed structural mass [kg] (default: the rig's m;
    substructuring with 2 % of m_m = 140 kg for Fig 10c).  Friction is off
    (linear analysis).  Input ``P`` [N] (external force, -m_m a_g), outputs
    ``x_c`` (calculated) and ``x`` (measured) [m].
    """
    r = copy_rig(rig)
    if physical_mass is not None:
        r.m = float(physical_mass)
    weights = _restoring_weights(r, restoring_force, force_measurement, k_m, subtract_mass, subtract_damping)
    plant = linearize(r, "displacement", outputs=("displacement", "velocity", "acceleration", "force", "pressure"))
    plant = ct.ss(plant.A, plant.B, plant.C, plant.D, inputs=["u"],
                  outputs=["x", "v_meas", "a_meas", "F_meas", "p_meas"], name="rig")
    meas = ct.ss([], [], [], [list(weights)], inputs=["x_c", "x", "v_meas", "a_meas", "F_meas", "p_meas"],
                 outputs=["f_meas"], name="restoring_force")
    solver = ct.ss([[0.0, 1.0], [0.0, -c_m / m_m]], [[0.0, 0.0], [1.0 / m_m, -1.0 / m_m]], [[1.0, 0.0]],
                   [[0.0, 0.0]], inputs=["P", "f"], outputs=["x_c"], name="solver")
    blocks = [plant, meas, solver]
    cmd = "x_c"
    chain = []
    if amplitude_T:
        chain.append(("amplitude_lead", phase_lead(amplitude_T, alpha)))
    if zoh_dt:
        chain.append(("zoh", zoh_delay(zoh_dt)))
    for name, tf in chain:
        blocks.append(ct.ss(tf, inputs=[cmd], outputs=[f"{name}_out"], name=name))
        cmd = f"{name}_out"
    blocks.append(ct.summing_junction(inputs=[cmd], output="u", name="command"))
    if delay_T:
        blocks.append(ct.ss(phase_lead(delay_T, alpha), inputs=["f_meas"], outputs=["f"], name="delay_lead"))
    else:
        blocks.append(ct.summing_junction(inputs=["f_meas"], output="f", name="delay_lead"))
    return ct.interconnect(blocks, inplist=["P"], outlist=["x_c", "x"], inputs=["P"], outputs=["x_c", "x"],
                           name="rpsd")


__all__ = ["RESTORING_FORCES", "fig10_variants", "rpsd_loop"]
