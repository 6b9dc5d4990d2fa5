"""Frequency responses of records: one :class:`FrequencyResponse`, two estimators.

* :func:`h1`: the H1 estimate with its coherence (Welch-averaged spectra), for
  lab records of any shape.
* :func:`dft_ratio`: the ratio of whole-record DFTs Y/U of a sweep that starts
  and ends at rest (the paper-era estimate of Fig 5a; no window, so no bias of
  segment averaging on a non-stationary chirp), with the mask of the frequencies
  the sweep excites instead of a coherence.

H1(f) = S_uy(f) / S_uu(f) from Welch-averaged spectra (``scipy.signal.csd``
and ``scipy.signal.welch``, Hann window, 50 % overlap), and the ordinary
coherence gamma^2 = |S_uy|^2 / (S_uu S_yy).  The segment length defaults to
the largest power of two not above n/6 (8192 points for a 60 s record at
1 kHz, as the UTFSM README's table uses), so that about ten segments are
averaged.  Unlike the DFT ratio, H1 needs no start or end at rest and tells by
its coherence where the record carries information.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True, eq=False)
class FrequencyResponse:
    """A frequency-response estimate: frequency [Hz], response [output unit / input unit] and,
    for H1, the coherence [-]; for the DFT ratio ``excited`` marks the frequencies the sweep
    excites (the coherence is then None)."""

    frequency: np.ndarray
    response: np.ndarray
    coherence: np.ndarray | None
    nperseg: int  #: samples per averaged segment (the record's length for the DFT ratio)
    method: str = "h1"  #: "h1" or "dft_ratio"
    excited: np.ndarray | None = None  #: DFT ratio: |U| >= min_level max|U|

    def at(self, frequencies: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(response, coherence) at the given frequencies [Hz], linearly interpolated
        (real and imaginary parts separately)."""
        f = np.asarray(frequencies, dtype=float)
        h = np.interp(f, self.frequency, self.response.real) + 1j * np.interp(f, self.frequency,
                                                                              self.response.imag)
        return h, np.interp(f, self.frequency, self._quality())

    def _quality(self) -> np.ndarray:
        return self.coherence if self.coherence is not None else np.asarray(self.excited, dtype=float)

    def band(self, min_coherence: float = 0.9, f_min: float = 0.0, f_max: float = math.inf) -> np.ndarray:
        """Mask of the frequencies in [f_min, f_max] with coherence >= min_coherence (the DFT
        ratio: the excited ones), 0 Hz excluded."""
        f = self.frequency
        return (f > 0) & (f >= f_min) & (f <= f_max) & (self._quality() >= min_coherence)


#: samples an H1 estimate needs (six segments of the shortest, 64)
MIN_SAMPLES = 384


def default_nperseg(n: int) -> int:
    """Largest power of two not above n/6 (at least 64): about ten averaged Hann segments."""
    if n < MIN_SAMPLES:
        raise ValueError(f"invalid record length = {n} samples: an H1 estimate needs at least {MIN_SAMPLES}")
    return 2 ** int(math.floor(math.log2(n / 6)))


def _signals(command: ArrayLike, output: ArrayLike, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The command and output as float arrays, checked: 1-D, the same shape, dt finite and > 0."""
    u = np.asarray(command, dtype=float)
    y = np.asarray(output, dtype=float)
    if u.shape != y.shape or u.ndim != 1:
        raise ValueError(f"invalid output shape = {y.shape}: must be 1-D and match the command {u.shape}")
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"invalid dt = {dt!r}: must be finite and > 0 [s]")
    return u, y


def h1(command: ArrayLike, output: ArrayLike, dt: float, nperseg: int | None = None) -> FrequencyResponse:
    """H1 estimate output/command and coherence of one record sampled at dt [s]."""
    u, y = _signals(command, output, dt)
    n = int(nperseg) if nperseg is not None else default_nperseg(u.size)
    if not 16 <= n <= u.size:
        raise ValueError(f"invalid nperseg = {n}: must be in [16, {u.size}] (the record's length)")
    from scipy import signal

    fs = 1.0 / dt
    kw = dict(fs=fs, nperseg=n, window="hann", detrend="constant")
    f, s_uy = signal.csd(u, y, **kw)
    _, s_uu = signal.welch(u, **kw)
    _, s_yy = signal.welch(y, **kw)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(s_uu > 0, s_uy / s_uu, np.nan)
        coh = np.where((s_uu > 0) & (s_yy > 0), np.abs(s_uy) ** 2 / (s_uu * s_yy), 0.0)
    return FrequencyResponse(frequency=f, response=h, coherence=np.clip(coh, 0.0, 1.0), nperseg=n)


def dft_ratio(command: ArrayLike, output: ArrayLike, dt: float, min_level: float = 0.05,
              from_rest: bool = True) -> FrequencyResponse:
    """The whole-record DFT ratio Y/U of a sweep sampled at dt [s].

    ``from_rest``: the first sample of each signal is removed first (the record starts at
    rest there; the sweep must also end at rest, faded out, so that no window is needed).
    The response is NaN where |U| < ``min_level`` max|U| (outside the sweep, ``excited``)."""
    u, y = _signals(command, output, dt)
    if from_rest:
        y, u = y - y[0], u - u[0]
    Y, U = np.fft.rfft(y), np.fft.rfft(u)
    ok = np.abs(U) >= min_level * np.max(np.abs(U))
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(ok, Y / U, np.nan)
    return FrequencyResponse(frequency=np.fft.rfftfreq(y.size, dt), response=h, coherence=None, nperseg=y.size,
                             method="dft_ratio", excited=ok)


def gain_phase(h: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Gain [-] and phase [deg] (unwrapped along the array) of a complex response."""
    h = np.asarray(h, dtype=complex)
    return np.abs(h), np.degrees(np.unwrap(np.angle(h)))


def command_band(command: ArrayLike, dt: float, share: float = 0.99) -> float:
    """Frequency [Hz] below which ``share`` of the command's (mean-removed) energy lies."""
    u = np.asarray(command, dtype=float)
    p = np.abs(np.fft.rfft(u - u.mean())) ** 2
    c = np.cumsum(p)
    if c[-1] <= 0:
        raise ValueError("invalid command: constant (no energy to estimate a frequency range from)")
    f = np.fft.rfftfreq(u.size, dt)
    return float(f[min(np.searchsorted(c, share * c[-1]), f.size - 1)])


__all__ = ["MIN_SAMPLES", "FrequencyResponse", "command_band", "default_nperseg", "dft_ratio", "gain_phase", "h1"]
