"""The thesis' own models of the UTFSM records, as independent reference baselines.

Quiroz (2022), MSc thesis, UTFSM; code and data: github.com/DanielMaurelE/vRTHS_AMBC_MRdamper
(MIT licence), summarised in ``../shared/real-data/utfsm-mts-mrdamper/README.md``:

* :func:`thesis_displacement`: the thesis' linear actuator model (chapter 6,
  ``modelo.mat``) G(s) = 9045.99 / ((s + 183.83)(s + 48.58)) from the command
  to the measured displacement, simulated by ``scipy.signal.lsim`` (the input
  linearly interpolated between samples).
* :func:`thesis_mr_force`: the thesis' MR-damper model (chapter 7, Spencer's
  modified Bouc-Wen, ``parametros.mat``) driven by the MEASURED displacement.
  Its equations, in the thesis' units N, mm, s and coil current i [A]::

      dy/dt = (alpha z + k0 (x - y) + c0 dx/dt) / (c0 + c1)
      dz/dt = -gamma |dx/dt - dy/dt| |z|^(n-1) z - beta (dx/dt - dy/dt) |z|^n + A (dx/dt - dy/dt)
      F     = c1 dy/dt + k1 (x - x0)

The actuator model is plain SciPy; the MR-damper law is the core's own element
(``_core.Dynamics.specimen_forces``, the kinematic driver: the thesis' parameters
in SI through :func:`spencer_rig_keys`, the current folded into the ``_a`` terms),
so the law is written once.  tests/python/spencer_oracle.py keeps an independent
NumPy transcription as the oracle it is checked against.  These are the baselines
our identified rigs are measured against, not a fit of ours.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import signal

from .. import _core
from ..rig import zhao2003

#: The thesis' command -> displacement model: numerator gain [1/s^2] and poles [rad/s].
THESIS_ACTUATOR = {"gain": 9045.99, "poles": (-183.83, -48.58)}


def thesis_actuator_tf() -> signal.TransferFunction:
    """G(s) = 9045.99 / ((s + 183.83)(s + 48.58)) [m/m] (DC gain 1.013)."""
    p1, p2 = THESIS_ACTUATOR["poles"]
    return signal.TransferFunction([THESIS_ACTUATOR["gain"]], np.polymul([1.0, -p1], [1.0, -p2]))


def thesis_displacement(time: ArrayLike, command: ArrayLike) -> np.ndarray:
    """Displacement [m] the thesis' G(s) predicts from the command [m], starting at rest."""
    t = np.asarray(time, dtype=float)
    _, y, _ = signal.lsim(thesis_actuator_tf(), np.asarray(command, dtype=float), t - t[0])
    return np.asarray(y, dtype=float)


@dataclass(frozen=True)
class SpencerParameters:
    """Modified Bouc-Wen (Spencer et al. 1997) parameters in the thesis' units N, mm, s."""

    alpha: float  #: [N/mm]
    c0: float  #: [N s/mm]
    c1: float  #: [N s/mm]
    k0: float  #: [N/mm]
    k1: float  #: [N/mm]
    x0: float  #: [mm]
    A: float  #: [-]
    beta: float  #: [mm^-2] (n = 2)
    gamma: float  #: [mm^-2]
    n: float  #: [-]


#: The thesis' current law (``parametros.mat``; its ``MR_BoucWen.m``: alpha = p4 i^2 + p5 i + p6,
#: gamma = p7 exp(p8 i), c0 = p9 i + p10, c1 = p11 i + p12, beta = gamma in its Simulink chart),
#: in its units N, mm, s, A: per parameter its coefficients of 1, i, i^2 (and the decay of exp(-d i)).
THESIS_LAW = {"alpha": (15.221, 41.508, -38.152), "c0": (0.92491, 7.6260), "c1": (9.8671, 78.337),
              "beta_gamma": 1.8941, "decay": 3.6561, "k0": 1.5013e-4, "k1": 1.2388, "x0": 2.3091e-3, "A": 300.0,
              "n": 2.0}
#: the field range the thesis fitted its law on [A]
THESIS_CURRENTS = (0.0, 1.0)


def thesis_mr_parameters(current: float) -> SpencerParameters:
    """The thesis' current-dependent fit (README: fitted to the May 2022 sinusoidal tests, 0-1 A)."""
    i = float(current)
    if not (math.isfinite(i) and THESIS_CURRENTS[0] <= i <= THESIS_CURRENTS[1]):
        raise ValueError(f"invalid current = {current!r}: the thesis' fit covers 0 ... 1 A")
    L = THESIS_LAW
    bg = L["beta_gamma"] * math.exp(-L["decay"] * i)
    return SpencerParameters(alpha=L["alpha"][2] * i**2 + L["alpha"][1] * i + L["alpha"][0],
                             c0=L["c0"][1] * i + L["c0"][0], c1=L["c1"][1] * i + L["c1"][0], k0=L["k0"], k1=L["k1"],
                             x0=L["x0"], A=L["A"], beta=bg, gamma=bg, n=L["n"])


def thesis_law_keys() -> dict[str, float | str]:
    """The thesis' whole current law as the core's ``[specimen]`` keys in SI (N, m, s, A): the
    law ``quiroz2022`` in the coil current (``mr_input = "current"``), identified on 0 ... 1 A;
    the current itself (``mr_current``) is the run's.  ``sh.rig_from_dict({"specimen": ...})``
    takes it (the names as the rig file spells them)."""
    L = THESIS_LAW
    n = L["n"]
    return {"mr_input": "current", "mr_law": "quiroz2022", "mr_alpha_a": 1e3 * L["alpha"][0],
            "mr_alpha_b": 1e3 * L["alpha"][1], "mr_alpha_c": 1e3 * L["alpha"][2], "mr_c0_a": 1e3 * L["c0"][0],
            "mr_c0_b": 1e3 * L["c0"][1], "mr_c1_a": 1e3 * L["c1"][0], "mr_c1_b": 1e3 * L["c1"][1],
            "mr_k0": 1e3 * L["k0"], "mr_k1": 1e3 * L["k1"], "mr_x0": 1e-3 * L["x0"], "mr_A": L["A"],
            "mr_beta": L["beta_gamma"] * 1e3**n, "mr_gamma": L["beta_gamma"] * 1e3**n, "mr_bw_decay": L["decay"],
            "mr_n": n, "mr_voltage": 0.0, "mr_law_min": THESIS_CURRENTS[0], "mr_law_max": THESIS_CURRENTS[1]}


def spencer_rig_keys(p: SpencerParameters) -> dict[str, float]:
    """The parameters as the core's ``[specimen]`` keys in SI units (N, m, s): N/mm -> N/m,
    N s/mm -> N s/m, mm -> m, mm^-n -> m^-n (z in m), the current folded into the
    ``_a`` terms (``_b`` = 0, ``mr_voltage`` = 0)."""
    return {"mr_alpha_a": 1e3 * p.alpha, "mr_alpha_b": 0.0, "mr_c0_a": 1e3 * p.c0, "mr_c0_b": 0.0,
            "mr_c1_a": 1e3 * p.c1, "mr_c1_b": 0.0, "mr_k0": 1e3 * p.k0, "mr_k1": 1e3 * p.k1, "mr_x0": 1e-3 * p.x0,
            "mr_A": p.A, "mr_beta": p.beta * 1e3**p.n, "mr_gamma": p.gamma * 1e3**p.n, "mr_n": p.n,
            "mr_voltage": 0.0}


def smoothed_motion(displacement: ArrayLike, dt: float, cutoff_hz: float = 200.0) -> tuple[np.ndarray, np.ndarray]:
    """(x, dx/dt) [m, m/s] from a measured displacement: the thesis' 4th-order
    Butterworth low-pass at 200 Hz (applied forward and backward, no phase
    shift) and central differences."""
    x = np.asarray(displacement, dtype=float)
    nyq = 0.5 / dt
    if cutoff_hz < nyq:
        sos = signal.butter(4, cutoff_hz / nyq, output="sos")
        x = signal.sosfiltfilt(sos, x)
    return x, np.gradient(x, dt)


def spencer_force(displacement: ArrayLike, dt: float, p: SpencerParameters, cutoff_hz: float = 200.0,
                  substeps: int = 10) -> np.ndarray:
    """Damper force [N] of the modified Bouc-Wen model driven by a measured
    displacement [m] sampled at dt [s] (smoothed as :func:`smoothed_motion`),
    starting with y = x and z = 0, the motion interpolated linearly between samples:
    the core's MR-damper element along that motion, integrated by classical RK4 with
    ``substeps`` steps per sample (0: from the element's rate bound)."""
    x, v = smoothed_motion(displacement, dt, cutoff_hz)
    rig = zhao2003()
    rig.effects.mr_damper = True
    for key, value in spencer_rig_keys(p).items():
        setattr(rig, key, value)
    dyn = _core.Dynamics(rig, _core.ControlMode.Free)
    return dyn.specimen_forces(x, v, float(dt), int(substeps))


def thesis_mr_force(displacement: ArrayLike, dt: float, current: float) -> np.ndarray:
    """The thesis' MR-damper force [N] at the coil current [A], driven by the measured displacement [m]."""
    return spencer_force(displacement, dt, thesis_mr_parameters(current))


__all__ = ["THESIS_ACTUATOR", "THESIS_CURRENTS", "THESIS_LAW", "SpencerParameters", "smoothed_motion",
           "spencer_rig_keys", "spencer_force", "thesis_actuator_tf", "thesis_displacement", "thesis_law_keys",
           "thesis_mr_force", "thesis_mr_parameters"]
