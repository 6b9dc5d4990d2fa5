"""A generic rig scaled from a record, for a lab that knows nothing of its actuator.

Every choice below is a round, documented engineering default
(docs/lab-records.md, "The generic start"); identification then moves the
fitted keys.  From the record: the peak displacement x_pk, the 99.9th
percentile of |velocity| v_pk (the displacement low-passed at 200 Hz and
differenced), the peak force F_pk and the frequency f_99 below which 99 % of
the command's energy lies.

======================  ==================================================================
supply p_s              21 MPa (3000 psi, the common industrial supply)
capacity F_cap          max(10 F_pk, 1 kN); piston area A = F_cap / p_s
half-stroke             max(5 x_pk, 10 mm); C_F_disp = 10 V / stroke, C_F_force = 10 V / F_cap
oil column K_a          V_t / (4 beta_e): V_t = 2 A stroke, beta_e = 1 GPa (oil with some air)
valve flow K_v          A max(5 v_pk, 50 mm/s) (rated velocity), K_s = 0.1 /V, linear valve
leakage C_l             0.1 % of the rated flow at the supply pressure
valve f_v, zeta_v       max(5 f_99, 20 Hz), 0.7
loop gain G_p           closed-loop corner 2 pi max(f_99 / 2, 1 Hz) = G_p C_F K_s K_v / A
masses m_p, m           F_cap x 1 g/N (at least 1 kg), m = m_p / 10
specimen k, c           least squares F = k x + c v + F_0 on the record (k >= 1 N/m, c >= 0)
effects                 valve dynamics, load pressure, piston mass, saturations on;
                        flow nonlinearity, friction and spring softening off
======================  ==================================================================
"""

from __future__ import annotations

import math

import numpy as np

from ..response import Response
from ..rig import EFFECTS, Rig, zhao2003
from .baselines import smoothed_motion
from .frf import command_band

P_SUPPLY = 21e6  #: [Pa]
BETA_E = 1.0e9  #: effective bulk modulus [Pa]
ON = ("servovalve_dynamics", "load_pressure", "piston_mass", "drive_saturation", "spool_saturation")


def record_scales(record: Response) -> dict[str, float]:
    """x_pk [m], v_pk [m/s], F_pk [N], f_99 [Hz] of a record (see the module docstring)."""
    x = np.asarray(record.displacement, dtype=float)
    _, v = smoothed_motion(x, record.dt)
    force = np.asarray(record.force, dtype=float) if "force" in record.channels else np.zeros(1)
    return {"x_pk": float(np.max(np.abs(x))), "v_pk": float(np.percentile(np.abs(v), 99.9)),
            "F_pk": float(np.max(np.abs(force))), "f_99": command_band(record.command, record.dt)}


def specimen_kc(record: Response) -> tuple[float, float]:
    """Linear stiffness k [N/m] and damping c [N s/m] of F = k x + c v + F_0 fitted to the record."""
    x, v = smoothed_motion(np.asarray(record.displacement, dtype=float), record.dt)
    X = np.column_stack([x, v, np.ones_like(x)])
    (k, c, _), *_ = np.linalg.lstsq(X, np.asarray(record.force, dtype=float), rcond=None)
    return max(float(k), 1.0), max(float(c), 0.0)


#: MR-damper start: Bouc-Wen A and n (Spencer et al. 1997: 301, 2), c1 / c0, and the
#: relative displacement over which z yields, as a fraction of the record's peak displacement
MR_A, MR_N, MR_C1_OVER_C0, MR_YIELD_FRACTION = 300.0, 2.0, 10.0, 0.05


def bingham_fit(record: Response) -> dict[str, float]:
    """F = f_y sgn(v) + c v + k x + m a + F_0 fitted by least squares to the record
    (x, v, a: the displacement low-passed at 200 Hz and differenced); f_y, c, m >= 0."""
    x, v = smoothed_motion(np.asarray(record.displacement, dtype=float), record.dt)
    a = np.gradient(v, record.dt)
    X = np.column_stack([np.tanh(v / (0.02 * np.max(np.abs(v)))), v, x, a, np.ones_like(x)])
    coef, *_ = np.linalg.lstsq(X, np.asarray(record.force, dtype=float), rcond=None)
    f_y, c, k, m, _ = (float(q) for q in coef)
    return {"f_y": max(f_y, 0.0), "c": max(c, 0.0), "k": k, "m": max(m, 0.0)}


def mr_damper_start(rig: Rig, record: Response) -> None:
    """Spencer MR-damper keys in ``rig`` from the record's Bingham fit (the damper's
    yield force f_y and post-yield damping c): high-velocity force c1 / (c0 + c1)
    (alpha z_u + c0 v) = f_y + c v with c1 = 10 c0, z_u = A x_y (yield over x_y = 5 %
    of the peak displacement), beta = gamma = A / (2 z_u^n); k1 = max(k, 0), k0 = 0,
    x0 = 0, voltage 0; the structure's own k, c at their floor (1 N/m, 0)."""
    b, s = bingham_fit(record), record_scales(record)
    ratio = MR_C1_OVER_C0 / (1.0 + MR_C1_OVER_C0)  # c1 / (c0 + c1)
    z_u = MR_A * max(MR_YIELD_FRACTION * s["x_pk"], 1e-6)
    rig.mr_c0_a, rig.mr_c0_b = max(b["c"], 1.0) / ratio, 0.0
    rig.mr_c1_a, rig.mr_c1_b = MR_C1_OVER_C0 * rig.mr_c0_a, 0.0
    rig.mr_alpha_a, rig.mr_alpha_b = max(b["f_y"], 1.0) / (ratio * z_u), 0.0
    rig.mr_A, rig.mr_n = MR_A, MR_N
    rig.mr_beta = rig.mr_gamma = MR_A / (2.0 * z_u**MR_N)
    rig.mr_k0, rig.mr_k1, rig.mr_x0, rig.mr_voltage = 0.0, max(b["k"], 0.0), 0.0, 0.0
    rig.k, rig.c, rig.m = 1.0, 0.0, max(b["m"], 0.1)


def bouc_wen_start(rig: Rig, record: Response) -> None:
    """Bouc-Wen keys (n = 1, A = 1) from the Bingham fit: ultimate force bw_k z_u = f_y,
    z_u = x_y = 5 % of the peak displacement, beta = gamma = 1 / (2 z_u); c, m from the fit."""
    b, s = bingham_fit(record), record_scales(record)
    z_u = max(MR_YIELD_FRACTION * s["x_pk"], 1e-6)
    rig.bw_A, rig.bw_n = 1.0, 1.0
    rig.bw_k = max(b["f_y"], 1.0) / z_u
    rig.bw_beta = rig.bw_gamma = 1.0 / (2.0 * z_u)
    rig.k, rig.c, rig.m = max(b["k"], 1.0), b["c"], max(b["m"], 0.1)


def specimen_start(rig: Rig, record: Response, specimen: str) -> None:
    """The generic start of the ``specimen`` kind's keys from the record (``linear``:
    :func:`specimen_kc`, already in :func:`generic_rig`)."""
    starts = {"linear": lambda r, rec: None, "bouc_wen": bouc_wen_start, "mr_damper": mr_damper_start}
    starts[specimen](rig, record)


def generic_rig(record: Response) -> Rig:
    """The generic rig scaled from ``record`` (a Response with time, command, displacement, force)."""
    s = record_scales(record)
    r = zhao2003()
    for name in EFFECTS:
        setattr(r.effects, name, name in ON)
    r.p_s = P_SUPPLY
    r.F_cap = max(10.0 * s["F_pk"], 1e3)
    r.A = r.F_cap / r.p_s
    r.stroke = max(5.0 * s["x_pk"], 0.01)
    r.C_F_disp, r.C_F_force = 10.0 / r.stroke, 10.0 / r.F_cap
    r.K_a = 2.0 * r.A * r.stroke / (4.0 * BETA_E)
    r.K_s, r.v_max, r.x_v_max = 0.1, 10.0, 1.0
    r.K_v = r.A * max(5.0 * s["v_pk"], 0.05)
    r.C_l = 1e-3 * r.K_v / r.p_s
    r.f_v, r.zeta_v = max(5.0 * s["f_99"], 20.0), 0.7
    w_c = 2.0 * math.pi * max(0.5 * s["f_99"], 1.0)
    r.G_p, r.G_d = w_c * r.A / (r.C_F_disp * r.K_s * r.K_v), 0.0
    r.m_p = max(1e-3 * r.F_cap, 1.0)
    r.m = 0.1 * r.m_p
    r.k, r.c = specimen_kc(record)
    r.F_c, r.x_contact = 0.0, 10.0 * r.stroke
    r.validate()
    return r


__all__ = ["BETA_E", "P_SUPPLY", "bingham_fit", "bouc_wen_start", "generic_rig", "mr_damper_start", "record_scales",
           "specimen_kc", "specimen_start"]
