"""The controllers of the paper's two test methods, apart from the plant.

``EftController`` and ``RpsdController`` wrap the core's controllers
(controllers.hpp): each reads the sensors at t_k and returns the command to hold
over the next controller sample.  ``sensors`` is the ``_core.Output`` that
``plant.observe()`` / ``plant.step(u)`` return, or one filled from a real rig's
I/O.  Stepping a plant and a controller by hand,

    plant = sh.make_plant(rig, "displacement")
    ctrl = sh.RpsdController(rig)
    sensors = plant.observe()
    for ag in ground_acceleration:
        u = ctrl.command(sensors, ground_acceleration=ag)
        status, sensors = plant.step(u)

reproduces ``sh.run_rpsd`` sample for sample (tests/python/test_seam.py);
examples/02_rpsd_controller.py wires it the way a laboratory would.
"""

from __future__ import annotations

from . import _core
from .loops import _document_fields, eft_config, rpsd_config
from .rig import Rig


class EftController:
    """Effective force testing (Fig 1a): P_eff = -m a_g plus the velocity feedback
    compensation (Eqs 9-10) through the 5 ms phase lead.

    Args:
        rig: the controller's model of the rig (the compensator's A, K_v, K_s,
            C_F_force, G_p, flow curve; and m when ``mass`` is None).
        compensation: ``"none"``, ``"linear"`` or ``"nonlinear"``.
        mass: m in P_eff = -m a_g [kg] (None: ``rig.m``).
        Keywords left at None take the core's ``EftConfig`` defaults (the paper's 0.5 ms, 5 ms, 0.1).
    """

    def __init__(self, rig: Rig, dt: float | None = None, compensation: str = "linear",
                 lead_T: float | None = None, alpha: float | None = None, mass: float | None = None,
                 compute_delay: int = 0):
        self._core = _core.EftController(eft_config(dt, compensation, lead_T, alpha, mass, compute_delay), rig)

    def reset(self) -> None:
        """At rest (compensator and compute delay cleared)."""
        self._core.reset()

    def command(self, sensors: _core.Output, ground_acceleration: float = 0.0) -> float:
        """The force command [N] to hold until the next sample, from the sensors at t_k and a_g(t_k) [m/s^2]."""
        return self._core.command(sensors, float(ground_acceleration))

    def command_output(self, sensors: _core.Output, ground_acceleration: float = 0.0) -> _core.EftOutput:
        """As ``command``, returning every channel of the sample (``.command``, ``.compensation``, ...)."""
        return self._core.command_output(sensors, float(ground_acceleration))

    @property
    def config(self) -> _core.EftConfig:
        return self._core.config

    @property
    def mass(self) -> float:
        """m in P_eff = -m a_g [kg]."""
        return self._core.mass


_document_fields(EftController, "EFT_CONFIG_FIELDS")


class RpsdController:
    """Real-time pseudodynamic testing (Figs 1b, 7): restoring force from the
    sensors (options a-d), delay compensation T_ld, the Eq (15) integration
    scheme, amplitude compensation T_d on the displacement command.

    Args:
        rig: the physical rig under test (its m is the structural mass behind the
            load cell); the defaults of k_m (rig.k), subtract_mass (rig.m, plus m_p
            for ``"actuator_pressure"``), subtract_damping (rig.c) and p A come from it.
        Others as ``sh.run_rpsd`` (``scheme``: ``"central_difference"`` or ``"explicit_newmark"``);
        keywords left at None take the core's ``RpsdConfig`` defaults.
    """

    def __init__(self, rig: Rig, dt: float | None = None, m_m: float | None = None, c_m: float | None = None,
                 k_m: float | None = None, scheme: str = "central_difference",
                 restoring_force: str = "measured_displacement", amplitude_T: float | None = None,
                 delay_T: float | None = None, alpha: float | None = None, force_measurement: str = "load_cell",
                 subtract_mass: float | None = None, subtract_damping: float | None = None,
                 compute_delay: int = 0):
        cfg = rpsd_config(dt, m_m, c_m, k_m, scheme, restoring_force, amplitude_T, delay_T, alpha,
                          force_measurement=force_measurement, subtract_mass=subtract_mass,
                          subtract_damping=subtract_damping, compute_delay=compute_delay)
        self._core = _core.RpsdController(cfg, rig)

    def reset(self) -> None:
        """At rest, the solver at d = 0."""
        self._core.reset()

    def command(self, sensors: _core.Output, ground_acceleration: float = 0.0, external_force: float = 0.0,
                restoring_force_error: float = 0.0) -> float:
        """The displacement command [m] to hold until the next sample, from the sensors at t_k,
        a_g [m/s^2], the external force into the solver [N] and an error added to f [N]."""
        return self._core.command(sensors, float(ground_acceleration), float(external_force),
                                  float(restoring_force_error))

    def command_output(self, sensors: _core.Output, ground_acceleration: float = 0.0, external_force: float = 0.0,
                       restoring_force_error: float = 0.0) -> _core.RpsdOutput:
        """As ``command``, returning every channel of the sample (``.command``, ``.calc_displacement``, ...)."""
        return self._core.command_output(sensors, float(ground_acceleration), float(external_force),
                                         float(restoring_force_error))

    @property
    def config(self) -> _core.RpsdConfig:
        return self._core.config

    @property
    def integrator_state(self) -> _core.IntegratorState:
        """d_k, v_k, a_k and the target d_{k+1} of the integration scheme."""
        return self._core.integrator_state

    @property
    def k_m(self) -> float:
        return self._core.k_m

    @property
    def subtract_mass(self) -> float:
        return self._core.subtract_mass

    @property
    def subtract_damping(self) -> float:
        return self._core.subtract_damping


_document_fields(RpsdController, "RPSD_CONFIG_FIELDS")

__all__ = ["EftController", "RpsdController"]
