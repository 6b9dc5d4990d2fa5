"""Excitations of the paper's tests, as plain NumPy arrays at the controller rate.

* ``sine`` and ``sine_sweep``: the paper's 0-10 Hz sweeps (2.3 kN and 8.9 kN
  effective force, 1.27 cm displacement, 0.15 g ground acceleration).  The paper
  does not give the sweep duration; ``SWEEP_DURATION`` = 40 s (a linear sweep
  at 0.25 Hz/s) is our choice: slow enough that the Fourier-amplitude ratio of a
  single sweep is a clean FRF estimate away from 0 Hz, fast enough that the
  2.3 kN sweep passes the 1.58 Hz resonance with a spool opening near the
  paper's "less than 10 %" for that test: 1.0 % uncompensated, 13.9 % with
  linear compensation (11.0 % over 20 s, 8.1 % over 10 s: the spool rows of
  ``servohydraulics reproduce``).
* ``ramp_and_release``: Fig 9, the structure pulled slowly by a ramp force into
  the solver, then released.
* ``read_at2`` / ``read_two_column`` / ``resample``: recorded ground motions
  (PEER NGA ``.AT2``, two-column time/acceleration text), in m/s^2 at dt.
* ``synthetic_earthquake``: a seeded Kanai-Tajimi filtered white noise with a
  Jennings-type envelope, so every example runs offline.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike
from scipy import signal

from .timegrid import DT, MAX_SAMPLES, time_axis  # noqa: F401 - DT, MAX_SAMPLES, time_axis: public here too
from .timegrid import positive as _positive

TWO_PI = 2.0 * math.pi
G = 9.80665  #: standard gravity [m/s^2]
SWEEP_DURATION = 40.0  #: default duration of the 0-10 Hz sweeps [s] (our choice, see module doc)

#: The paper's sweep amplitudes (SI).
SWEEP_FORCE_SMALL = 2.3e3  #: EFT sweep, Fig 3 [N]
SWEEP_FORCE_LARGE = 8.9e3  #: EFT sweep, Fig 4 [N]
SWEEP_DISPLACEMENT = 0.0127  #: displacement sweep, Fig 5 [m]
SWEEP_GROUND_ACCELERATION = 0.15 * G  #: RPsD sweep, Fig 8 [m/s^2]


def sine(amplitude: float, frequency: float, duration: float, dt: float = DT, phase: float = 0.0) -> np.ndarray:
    """amplitude * sin(2 pi f t + phase); frequency [Hz], duration and dt [s]."""
    _positive("frequency", frequency)
    for name, v in (("amplitude", amplitude), ("phase", phase)):
        if not math.isfinite(v):
            raise ValueError(f"invalid {name} = {v!r}: must be finite")
    t = time_axis(duration, dt)
    return amplitude * np.sin(2 * np.pi * frequency * t + phase)


def sine_sweep(amplitude: float, f0: float = 0.0, f1: float = 10.0, duration: float = SWEEP_DURATION,
               dt: float = DT, taper: float = 0.0) -> np.ndarray:
    """Linear sine sweep from f0 to f1 [Hz] over duration [s]: amplitude sin(2 pi (f0 t + (f1-f0) t^2/(2 T))).

    taper [s]: optional half-cosine fade-in and fade-out, 0 = none (the paper's sweeps start at 0 Hz,
    which already starts smoothly).
    """
    if not (math.isfinite(f0) and f0 >= 0):
        raise ValueError(f"invalid f0 = {f0!r}: must be finite and >= 0 [Hz]")
    _positive("f1", f1)
    if f1 <= f0:
        raise ValueError(f"invalid f1 = {f1!r}: must be above f0 = {f0} [Hz]")
    t = time_axis(duration, dt)
    x = amplitude * np.sin(2 * np.pi * (f0 * t + 0.5 * (f1 - f0) / duration * t**2))
    if taper > 0:
        w = np.ones_like(t)
        n = min(int(round(taper / dt)), t.size // 2)
        ramp = 0.5 * (1 - np.cos(np.pi * np.arange(n) / n))
        w[:n] = ramp
        w[t.size - n:] = ramp[::-1]
        x *= w
    return x


def linear_chirp(duration: float, dt: float, f0: float, f1: float, amplitude: float,
                 ramp: float = 0.5, tail: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Linear sine sweep from f0 to f1 [Hz] over ``duration`` [s], amplitude [m or N],
    with half-cosine fades of ``ramp`` seconds at both ends, then ``tail``
    seconds of zeros (for the response to settle).  Returns (time [s], signal)."""
    t = time_axis(duration + tail, dt)
    u = amplitude * signal.chirp(t, f0=f0, t1=duration, f1=f1, method="linear", phi=-90.0)
    if ramp > 0:
        w = np.clip(np.minimum(t, duration - t) / ramp, 0.0, 1.0)
        u *= 0.5 - 0.5 * np.cos(math.pi * w)
    u[t > duration] = 0.0
    return t, u


def sweep_frequency(t: ArrayLike, f0: float = 0.0, f1: float = 10.0, duration: float = SWEEP_DURATION) -> np.ndarray:
    """Instantaneous frequency of ``sine_sweep`` at times t [Hz]."""
    return f0 + (f1 - f0) * np.asarray(t) / duration


def ramp_and_release(peak_force: float, ramp_time: float = 5.0, hold_time: float = 1.0,
                     free_time: float = 10.0, dt: float = DT) -> np.ndarray:
    """Fig 9: an external force into the solver ramped from 0 to peak_force [N] over ramp_time [s]
    (slow compared to the 0.63 s period), held for hold_time [s], then set to zero (release) and
    left at zero for free_time [s].  With the paper's k = 700.8 kN/m, 1.6 cm needs 11.2 kN."""
    for name, v in (("ramp_time", ramp_time), ("free_time", free_time)):
        _positive(name, v)
    if not (math.isfinite(hold_time) and hold_time >= 0):
        raise ValueError(f"invalid hold_time = {hold_time!r}: must be finite and >= 0 [s]")
    n_ramp = int(round(ramp_time / dt))
    n_hold = int(round(hold_time / dt))
    n_free = int(round(free_time / dt)) + 1
    # Half-cosine ramp: starts and ends with zero slope so the pull excites no vibration.
    ramp = peak_force * 0.5 * (1 - np.cos(np.pi * np.arange(n_ramp) / n_ramp))
    return np.concatenate([ramp, np.full(n_hold, float(peak_force)), np.zeros(n_free)])


def release_index(ramp_time: float = 5.0, hold_time: float = 1.0, dt: float = DT) -> int:
    """Sample index at which ``ramp_and_release`` drops the force to zero."""
    return int(round(ramp_time / dt)) + int(round(hold_time / dt))


def resample(t: ArrayLike, a: ArrayLike, dt: float = DT, duration: float | None = None) -> np.ndarray:
    """Resamples a record a(t) onto t_k = k dt (linear interpolation, zero after the end).

    When the record's own step is coarser than dt this is what a DSP playing the
    record would do; no anti-alias filter is needed for upsampling.  When it is
    finer, the record is first low-pass filtered (zero phase) below the new Nyquist.
    """
    t = np.asarray(t, dtype=float)
    a = np.asarray(a, dtype=float)
    if t.ndim != 1 or a.shape != t.shape or t.size < 2:
        raise ValueError(f"invalid record shapes t {t.shape}, a {a.shape}: need equal 1-D arrays of >= 2 samples")
    if np.any(np.diff(t) <= 0):
        raise ValueError("invalid record time: must be strictly increasing")
    if not np.all(np.isfinite(a)):
        raise ValueError("invalid record: accelerations must be finite")
    _positive("dt", dt)
    step = float(np.median(np.diff(t)))
    if step < dt:
        sos = signal.butter(8, 0.8 * (0.5 / dt) / (0.5 / step), output="sos")
        a = signal.sosfiltfilt(sos, a)
    if duration is None:
        duration = t[-1] - t[0]
    tk = time_axis(duration, dt)
    return np.interp(tk + t[0], t, a, left=0.0, right=0.0)


def read_at2(path: str | Path, dt: float = DT) -> tuple[np.ndarray, dict]:
    """Reads a PEER NGA ``.AT2`` file (acceleration in g) -> (a_g in m/s^2 at dt, header info).

    The fourth header line holds ``NPTS= n, DT= step SEC`` (either order, commas optional).
    """
    lines = Path(path).read_text().splitlines()
    if len(lines) < 5:
        raise ValueError(f"invalid AT2 file {path}: fewer than 5 lines")
    head = lines[3].upper()
    m_n = re.search(r"NPTS\s*=?\s*(\d+)", head)
    m_dt = re.search(r"DT\s*=?\s*([0-9.Ee+-]+)", head)
    if not (m_n and m_dt):
        raise ValueError(f"invalid AT2 header line 4 in {path}: {lines[3]!r} (need NPTS= and DT=)")
    n, step = int(m_n.group(1)), float(m_dt.group(1))
    values = np.array(" ".join(lines[4:]).split(), dtype=float)
    if values.size < n:
        raise ValueError(f"invalid AT2 file {path}: NPTS = {n} but {values.size} values")
    a = values[:n] * G
    t = np.arange(n) * step
    info = {"title": lines[1].strip(), "npts": n, "dt": step, "units": "g"}
    return resample(t, a, dt), info


def read_two_column(path: str | Path, dt: float = DT, scale: float = 1.0) -> np.ndarray:
    """Reads whitespace- or comma-separated (time [s], acceleration) text, '#' comments allowed;
    scale converts the acceleration to m/s^2 (e.g. 9.80665 for g).  Returns a_g at dt."""
    data = np.loadtxt(path, comments="#", delimiter=None if "," not in Path(path).read_text()[:2000] else ",")
    if data.ndim != 2 or data.shape[1] < 2:
        raise ValueError(f"invalid two-column file {path}: shape {data.shape}")
    return resample(data[:, 0], data[:, 1] * scale, dt)


def synthetic_earthquake(duration: float = 20.0, pga: float = 0.15 * G, dt: float = DT, seed: int = 0,
                         f_g: float = 2.5, zeta_g: float = 0.6, t_rise: float = 2.0,
                         t_strong: float = 6.0, decay: float = 0.35) -> np.ndarray:
    """A seeded synthetic ground acceleration [m/s^2]: white noise through the Kanai-Tajimi filter
    H(s) = (2 zeta_g w_g s + w_g^2)/(s^2 + 2 zeta_g w_g s + w_g^2) (firm soil: f_g = 2.5 Hz,
    zeta_g = 0.6), shaped by a Jennings envelope (t/t_rise)^2, 1, exp(-decay (t - t_rise - t_strong)),
    high-passed at 0.1 Hz (zero phase) so the ground displacement does not drift, scaled to pga."""
    _positive("duration", duration)
    _positive("pga", pga)
    t = time_axis(duration, dt)
    rng = np.random.default_rng(seed)
    w = rng.standard_normal(t.size)
    wg = 2 * np.pi * f_g
    b, a = signal.bilinear([2 * zeta_g * wg, wg**2], [1.0, 2 * zeta_g * wg, wg**2], fs=1 / dt)
    x = signal.lfilter(b, a, w)
    env = np.where(t < t_rise, (t / t_rise) ** 2,
                   np.where(t < t_rise + t_strong, 1.0, np.exp(-decay * (t - t_rise - t_strong))))
    x = x * env
    sos = signal.butter(2, 0.1, btype="highpass", fs=1 / dt, output="sos")
    x = signal.sosfiltfilt(sos, x)
    return x * (pga / np.max(np.abs(x)))
