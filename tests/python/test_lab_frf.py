"""H1 frequency responses against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from servohydraulics.identification import baselines, frf


def test_h1_matches_a_known_digital_filter():
    """White-noise input through a known IIR filter: H1 equals its closed-form
    response (freqz) and the coherence is 1 without noise."""
    rng = np.random.default_rng(1)
    dt = 1e-3
    u = rng.standard_normal(60_000)
    b, a = signal.butter(2, 30.0 * 2 * dt)  # 30 Hz low-pass
    y = signal.lfilter(b, a, u)
    est = frf.h1(u, y, dt)
    assert est.nperseg == 8192
    sel = (est.frequency > 1) & (est.frequency < 100)
    _, h = signal.freqz(b, a, worN=est.frequency[sel], fs=1 / dt)
    np.testing.assert_allclose(est.response[sel], h, rtol=0, atol=0.02)
    assert np.min(est.coherence[sel]) > 0.999


def test_coherence_of_output_noise_matches_closed_form():
    """y = u + n with independent white n: gamma^2 = S_uu / (S_uu + S_nn) = 1 / (1 + sigma_n^2 / sigma_u^2)."""
    rng = np.random.default_rng(2)
    u = rng.standard_normal(120_000)
    y = u + 0.5 * rng.standard_normal(u.size)
    est = frf.h1(u, y, 1e-3)
    sel = est.frequency > 0
    assert np.mean(est.coherence[sel]) == pytest.approx(1 / 1.25, abs=0.01)
    assert np.mean(np.abs(est.response[sel])) == pytest.approx(1.0, abs=0.01)


def test_thesis_actuator_response_matches_its_transfer_function():
    """lsim of the thesis' G(s) on a chirp, seen through H1, reproduces G(j w)."""
    dt = 1e-3
    t = np.arange(60_000) * dt
    u = signal.chirp(t, 0.1, t[-1], 30.0) * 1e-3
    y = baselines.thesis_displacement(t, u)
    est = frf.h1(u, y, dt)
    f = np.array([2.0, 5.0, 10.0, 20.0])  # at 1 Hz the chirp crosses a segment too fast (Welch bias 2 %)
    h, coh = est.at(f)
    _, g = signal.freqresp(baselines.thesis_actuator_tf(), 2 * np.pi * f)
    np.testing.assert_allclose(np.abs(h), np.abs(g), rtol=0.01)
    np.testing.assert_allclose(np.angle(h), np.angle(g), atol=np.radians(1.0))
    assert np.min(coh) > 0.99


def test_command_band_of_a_sine_is_its_frequency():
    t = np.arange(20_000) * 1e-3
    assert frf.command_band(np.sin(2 * np.pi * 7.0 * t), 1e-3) == pytest.approx(7.0, abs=0.1)


def test_bad_input():
    with pytest.raises(ValueError, match="at least 384"):
        frf.h1(np.zeros(100), np.zeros(100), 1e-3)
    with pytest.raises(ValueError, match="invalid output shape"):
        frf.h1(np.zeros(1000), np.zeros(999), 1e-3)
