"""The optional sensor and converter blocks of the EFT and RPsD loops
(loop_converters.hpp): off by default and then bit-for-bit the loop without them;
contracts of each block measured through the loop."""

from __future__ import annotations

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core

DT = 5e-4


def _ag(n: int = 4000, seed: int = 3) -> np.ndarray:
    """A band-limited ground acceleration [m/s^2] (2 s at 2 kHz)."""
    t = np.arange(n) * DT
    return 0.8 * np.sin(2 * np.pi * 1.3 * t) * np.sin(np.pi * t / t[-1]) + 0.3 * np.sin(2 * np.pi * 4.1 * t + seed)


def _rpsd(**kw):
    return sh.run_rpsd(sh.zhao2003(), ground_acceleration=_ag(), restoring_force="measured_force", delay_T=0.0, **kw)


def _same(a: sh.Response, b: sh.Response) -> None:
    for name in a.channels:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_default_is_off_and_bit_for_bit():
    c = sh.loop_converters()
    assert not c.active and not _core.LoopConverters().active
    _same(_rpsd(), _rpsd(converters=c))
    ag = _ag()
    _same(sh.run_eft(sh.zhao2003(), ground_acceleration=ag), sh.run_eft(sh.zhao2003(), ground_acceleration=ag,
                                                                      converters=c))


def test_force_quantizer_error_is_at_most_half_an_lsb():
    q = 50.0  # [N], coarse so that it shows
    r = _rpsd(converters=sh.loop_converters(force=sh.sensor_channel(quantum=q)))
    f, fm = r.force, r.measured_restoring_force  # option (c): f = F_meas
    err = fm - f
    assert np.max(np.abs(err)) <= q / 2 * (1 + 1e-12)
    np.testing.assert_allclose(fm / q, np.round(fm / q), atol=1e-9)  # on the grid
    assert np.std(err) == pytest.approx(q / np.sqrt(12), rel=0.1)  # uniform quantization error
    assert not np.array_equal(r.displacement, _rpsd().displacement)  # the controller saw it


def test_force_saturation_clips_at_the_range():
    r = _rpsd(converters=sh.loop_converters(force=sh.sensor_channel(range=(-2e3, 2e3))))
    f, fm = r.force, r.measured_restoring_force
    assert np.max(np.abs(f)) > 2e3  # the range acts
    np.testing.assert_array_equal(fm, np.clip(f, -2e3, 2e3))


def test_noise_standard_deviation_measured_equals_set():
    sigma = 30.0  # [N]
    r = _rpsd(converters=sh.loop_converters(force=sh.sensor_channel(sigma=sigma), seed=11))
    err = r.measured_restoring_force - r.force
    n = err.size  # 4000: the std estimate has a relative sd of 1/sqrt(2n) = 1.1 %
    assert np.std(err, ddof=1) == pytest.approx(sigma, rel=4.5 / np.sqrt(2 * n))
    assert abs(np.mean(err)) < 4.5 * sigma / np.sqrt(n)
    lag1 = np.corrcoef(err[1:], err[:-1])[0, 1]  # white: held over one sample, new each sample
    assert abs(lag1) < 4.5 / np.sqrt(n)
    again = _rpsd(converters=sh.loop_converters(force=sh.sensor_channel(sigma=sigma), seed=11))
    np.testing.assert_array_equal(again.measured_restoring_force, r.measured_restoring_force)


def test_unit_delay_shifts_by_exactly_one_sample():
    r = _rpsd(converters=sh.loop_converters(force=sh.sensor_channel(unit_delay=True)))
    f, fm = r.force, r.measured_restoring_force
    assert fm[0] == 0.0
    np.testing.assert_array_equal(fm[1:], f[:-1])


def test_command_unit_delay_equals_one_sample_of_compute_delay():
    """The D/A's unit delay and the controller's compute delay of one sample both hold
    the command one sample longer: the plant sees the same commands, bit for bit."""
    ag = _ag()
    a = sh.run_eft(sh.zhao2003(), ground_acceleration=ag, converters=sh.loop_converters(command_unit_delay=True))
    b = sh.run_eft(sh.zhao2003(), ground_acceleration=ag, compute_delay=1)
    for name, _unit in _core.PLANT_CHANNELS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_command_quantizer_through_the_block():
    io = _core.LoopIo(sh.loop_converters(command_quantum=0.25, command_range=(-1.0, 1.0)))
    u = np.linspace(-1.6, 1.6, 1001)
    y = np.array([io.actuate(v) for v in u])
    assert np.all(np.abs(y - np.clip(u, -1.0, 1.0)) <= 0.125 + 1e-15)
    assert set(np.round(y / 0.25)) <= set(range(-4, 5))
    assert io.actuate(0.125) == 0.25 and io.actuate(-0.125) == -0.25  # half away from zero (MATLAB round)


def test_measured_channels_of_the_block():
    io = _core.LoopIo(sh.loop_converters(displacement=sh.sensor_channel(gain=2.0, unit_delay=True),
                                         velocity=sh.sensor_channel(quantum=0.1)))
    assert io.measure(1.0, 0.26, 5.0) == (0.0, pytest.approx(0.3), 5.0)
    assert io.measure(3.0, -0.04, 6.0) == (2.0, -0.0, 6.0)


def test_bad_input_names_the_field():
    with pytest.raises(ValueError, match="sigma"):
        sh.sensor_channel(sigma=-1.0)
    with pytest.raises(ValueError, match="range"):
        sh.sensor_channel(range=(1.0, -1.0))
    with pytest.raises(ValueError, match="converters"):
        sh.run_rpsd(sh.zhao2003(), ground_acceleration=_ag(), converters="noisy")
    c = _core.LoopConverters()
    c.force.noise.sigma = float("nan")
    with pytest.raises(ValueError, match=r"converters\.force\.noise\.sigma"):
        c.validate()


def test_loop_converters_choose_the_noise_generator():
    """The displacement channel's noise is sigma w_k of the chosen generator (the core's
    GaussianSequence, converters.hpp): read back through option (b), f = k_m x_meas."""
    rig = sh.zhao2003()
    ag = np.zeros(200)
    sigma = 1e-4
    for name, gen in (("mersenne_twister", _core.NoiseGenerator.MersenneTwister),
                      ("simulink", _core.NoiseGenerator.SimulinkRandomNumber)):
        conv = sh.loop_converters(displacement=sh.sensor_channel(sigma=sigma), seed=7, generator=name)
        r = sh.run_rpsd(rig, ground_acceleration=ag, converters=conv, k_m=1e6, delay_T=0.0)
        noise = np.asarray(r.channels["measured_restoring_force"]) / 1e6 - np.asarray(r.channels["displacement"])
        w = _core.GaussianSequence(7, gen)
        expected = sigma * np.array([w.next() for _ in ag])
        np.testing.assert_allclose(noise, expected, rtol=1e-9, atol=1e-15)
    with pytest.raises(ValueError, match="generator"):
        sh.loop_converters(generator="bogus")
