"""Signal analysis for the test methods: FRFs from sweeps, free-vibration identification."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, signal


def fourier_ratio(output: np.ndarray, reference: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """|FFT(output)| / |FFT(reference)| of one record -> (frequency [Hz], ratio [-]).

    For a sine sweep this is the amplitude of the frequency response (the paper
    plots Fourier amplitudes of the measured force against the command)."""
    y = np.asarray(output, dtype=float)
    u = np.asarray(reference, dtype=float)[: y.size]
    Y, U = np.fft.rfft(y), np.fft.rfft(u)
    f = np.fft.rfftfreq(y.size, dt)
    with np.errstate(divide="ignore", invalid="ignore"):
        return f, np.abs(Y) / np.abs(U)


def h1_frf(output: np.ndarray, reference: np.ndarray, dt: float, segment: float = 10.0) -> tuple[np.ndarray,
                                                                                               np.ndarray]:
    """H1 estimate S_uy / S_uu (Welch, Hann, segment [s], 50 % overlap) -> (frequency [Hz], complex H)."""
    fs = 1.0 / dt
    n = int(round(segment * fs))
    f, Suy = signal.csd(reference, output, fs=fs, nperseg=n)
    _, Suu = signal.welch(reference, fs=fs, nperseg=n)
    return f, Suy / Suu


@dataclass
class FreeVibration:
    """Identified free vibration x(t) = X exp(-zeta w_n t) cos(w_d t + phi) + x_inf."""

    frequency: float  #: damped natural frequency f_d [Hz]
    damping_ratio: float  #: zeta [-] (negative: the response grows)
    amplitude: float  #: X [same unit as the signal]
    offset: float  #: x_inf
    rms_error: float  #: fit residual relative to X [-]


def identify_free_vibration(x: np.ndarray, dt: float, start: int = 0, duration: float = 4.0) -> FreeVibration:
    """Fits a damped cosine to x[start : start + duration/dt] by least squares.

    The frequency is started from the zero-padded FFT peak of the window; zeta from 0.
    Robust to the small oil-column ripple that makes peak picking unreliable."""
    n = int(round(duration / dt))
    y = np.asarray(x, dtype=float)[start: start + n]
    if y.size < 16:
        raise ValueError(f"invalid window: {y.size} samples from start = {start}")
    t = np.arange(y.size) * dt
    yc = y - y.mean()
    nfft = 16 * y.size
    spec = np.abs(np.fft.rfft(yc * np.hanning(y.size), nfft))
    freqs = np.fft.rfftfreq(nfft, dt)
    f0 = freqs[np.argmax(spec[1:]) + 1]

    def model(p: np.ndarray) -> np.ndarray:
        X, z, f, phi, c = p
        wn = 2 * np.pi * f / np.sqrt(max(1 - z * z, 1e-9))
        return X * np.exp(-z * wn * t) * np.cos(2 * np.pi * f * t + phi) + c

    X0 = np.abs(yc).max()
    best = None
    for phi0 in (0.0, np.pi / 2, np.pi, -np.pi / 2):
        r = optimize.least_squares(lambda p: model(p) - y, [X0, 0.0, f0, phi0, y.mean()],
                                   bounds=([0, -0.9, 0.5 * f0, -10, -np.inf], [np.inf, 0.9, 2 * f0, 10, np.inf]))
        if best is None or r.cost < best.cost:
            best = r
    X, z, f, _, c = best.x
    rms = float(np.sqrt(np.mean(best.fun**2)) / max(X, 1e-300))
    return FreeVibration(frequency=float(f), damping_ratio=float(z), amplitude=float(X), offset=float(c),
                         rms_error=rms)
