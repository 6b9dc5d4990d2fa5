"""The thesis' Spencer (modified Bouc-Wen) baseline, the core's MR element driven along the
motion, against a closed form and an independent NumPy transcription (spencer_oracle.py)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from spencer_oracle import spencer_force_lsoda, spencer_force_rk4

from servohydraulics.identification import baselines as b


def test_spencer_without_hysteresis_is_its_linear_closed_form():
    """With A = 0 the evolutionary variable z stays 0 and the model is linear:
    F/X = c1 s (k0 + c0 s)/((c0 + c1) s + k0) + k1 (N, mm).  Steady-state sine response."""
    p = dataclasses.replace(b.thesis_mr_parameters(0.5), A=0.0, k0=50.0, c0=2.0, c1=10.0, x0=0.0)
    dt, f, X = 1e-3, 2.0, 3.0  # mm
    t = np.arange(6000) * dt
    x_m = 1e-3 * X * np.sin(2 * np.pi * f * t)
    F = b.spencer_force(x_m, dt, p)
    s = 2j * np.pi * f
    H = p.c1 * s * (p.k0 + p.c0 * s) / ((p.c0 + p.c1) * s + p.k0) + p.k1
    expected = X * np.abs(H) * np.sin(2 * np.pi * f * t + np.angle(H))
    tail = t > 3.0  # (c0 + c1)/k0 = 0.24 s: the start has decayed
    assert np.max(np.abs(F[tail] - expected[tail])) < 2e-3 * X * np.abs(H)


def test_thesis_parameters_follow_the_readme():
    p0, p1 = b.thesis_mr_parameters(0.0), b.thesis_mr_parameters(1.0)
    assert p0.alpha == pytest.approx(15.221) and p1.alpha == pytest.approx(-38.152 + 41.508 + 15.221)
    assert p1.c1 == pytest.approx(78.337 + 9.8671) and p1.beta == pytest.approx(1.8941 * np.exp(-3.6561))
    with pytest.raises(ValueError, match="invalid current"):
        b.thesis_mr_parameters(2.0)


@pytest.mark.parametrize("current", [0.0, 1.0])
def test_core_baseline_equals_the_numpy_oracle(current):
    """The core element through the kinematic driver against the NumPy transcription on a 2 mm
    chirp to 15 Hz (peak 90 mm/s, the records' range) with the thesis' 0 A (stiffest z) and 1 A
    parameters: the same RK4 scheme agrees to round-off (1e-9 of the force's std; the core runs
    in SI, the oracle in mm), and SciPy's LSODA (rtol 1e-6) within 2e-3 of it everywhere."""
    dt = 1e-3
    t = np.arange(8000) * dt
    x_m = 2e-3 * np.sin(2 * np.pi * (0.5 * t + 0.9 * t**2))
    p = b.thesis_mr_parameters(current)
    core = b.spencer_force(x_m, dt, p)
    x, v = b.smoothed_motion(x_m, dt)
    same_scheme, lsoda = spencer_force_rk4(x, v, dt, p, 10), spencer_force_lsoda(x, v, dt, p)
    assert np.max(np.abs(core - same_scheme)) < 1e-9 * np.std(lsoda)
    assert np.max(np.abs(core - lsoda)) < 2e-3 * np.std(lsoda)
    with pytest.raises(ValueError, match="invalid substeps = -1"):
        b.spencer_force(x_m, dt, p, substeps=-1)
