"""Statistics of a simulation-error least-squares fit: lag-1 autocorrelation, the
AR(1) effective sample size, and the one covariance estimator every fit of the
package uses (``sh.identify``, ``sh.diagnose``).

**The covariance rule: a HAC (Newey-West) sandwich, computed from an SVD.**

    cov = D (J_s' J_s)^+ Omega (J_s' J_s)^+ D,   J_s = J D,

with J the Jacobian of the stacked residuals r in the fitting coordinates, D the
parameters' scales (columns differ by ten orders of magnitude), and Omega the
long-run covariance of the scores J_s,t r_t with Bartlett weights, summed over the
series (record, channel) the residual stacks (no lag crosses two series), the lag
truncation per series from the AR(1) plug-in rule of Andrews (1991).

Why this one.  The residual of a simulation-error fit is autocorrelated (model
error, coloured noise, a response that integrates the noise).  The alternative
the package had, s^2 (J'J)^-1 inflated by n / n_eff(AR(1)), assumes one AR(1)
for the whole residual and the same correction for every parameter; the sandwich
weights the autocorrelation by each parameter's own score series, so a key the
slow drift loads on gets the wider interval and one the fast content determines
does not.  It needs no noise model, reduces to s^2 (J'J)^-1 for white residuals,
and stays valid for weighted residuals (the channel weights of ``sh.identify``).
Its known weakness: with strongly persistent residuals and few effective samples
it under-covers a little (AR(1) noise with phi = 0.95, about 60 effective samples:
8 and 9 of 10 intervals cover, ``test_identify.py``); against an AR(1) mean it
recovers the long-run variance within 15 % (``test_identification.py``).  The
paper-era fits (``paper.py``), ``sh.identify`` (``records.py``) and ``sh.diagnose``
(``diagnosis/engine.py``) all call :func:`covariance`.

The pseudo-inverse is taken from the SVD of the scaled Jacobian: a direction
whose singular value is below ``RCOND`` times the largest is not determined by
the data, and every parameter that direction moves (|loading| >= ``NULL_LOADING``)
gets an infinite variance and is flagged "not identified" (the earlier rules
dropped such directions in a pseudo-inverse and reported a zero-width interval:
``loop_delay`` with the effect off at [0.002, 0.002]).  The result is symmetric
by construction and its correlation lies in [-1, 1] (NaN where a variance is
infinite).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np
from numpy.typing import ArrayLike

#: singular values of the scaled Jacobian below RCOND * the largest span directions the data do not determine
RCOND = 1e-6
#: a parameter whose loading on such a direction is at least this is "not identified"
NULL_LOADING = 1e-2
#: the confidence level of every reported interval
LEVEL = 0.95


def quantile(level: float = LEVEL) -> float:
    """The two-sided normal quantile of ``level`` (1.95996 for 95 %)."""
    if not 0.0 < level < 1.0:
        raise ValueError(f"invalid level = {level!r}: must be in (0, 1)")
    return NormalDist().inv_cdf(0.5 + level / 2.0)


def lag1_autocorrelation(x: ArrayLike) -> float:
    """Lag-1 autocorrelation of a series about its mean [-] (0 for a constant series)."""
    e = np.asarray(x, dtype=float)
    e = e - e.mean()
    den = float(e @ e)
    return float(e[:-1] @ e[1:]) / den if den > 0 else 0.0


def ar1_coefficient(x: ArrayLike) -> float:
    """The lag-1 autocorrelation clipped to [0, 0.999]: the AR(1) coefficient of
    a residual series as the effective-sample-size and bandwidth rules use it
    (they need 0 <= rho < 1)."""
    return min(max(lag1_autocorrelation(x), 0.0), 0.999)


def ar1_effective_n(n: float, rho: float) -> float:
    """Effective sample size of n samples of an AR(1) series with coefficient rho:
    n (1 - rho) / (1 + rho)."""
    return n * (1.0 - rho) / (1.0 + rho)


def bartlett_bandwidth(e: np.ndarray) -> int:
    """Newey-West lag truncation for a series from the AR(1) plug-in rule of
    Andrews (1991) for the Bartlett kernel: 1.1447 (alpha n)^(1/3), alpha =
    4 rho^2 / ((1 - rho)^2 (1 + rho)^2), rho the lag-1 autocorrelation; at most n/2."""
    n = e.size
    rho = ar1_coefficient(e)
    alpha = 4 * rho ** 2 / ((1 - rho) ** 2 * (1 + rho) ** 2)
    return int(min(max(math.ceil(1.1447 * (alpha * n) ** (1 / 3)), 1), n // 2))


def long_run_covariance(scores: np.ndarray, r: np.ndarray, lengths: list[int]) -> np.ndarray:
    """Omega = sum over series of the Bartlett-weighted autocovariances of the scores
    S_t = scores_t r_t up to each series' ``bartlett_bandwidth`` (symmetric)."""
    p = scores.shape[1]
    omega = np.zeros((p, p))
    iu, ju = np.triu_indices(p)
    a = 0
    for m in lengths:
        S = scores[a:a + m] * r[a:a + m, None]
        L = bartlett_bandwidth(r[a:a + m])
        nfft = 1 << int(math.ceil(math.log2(2 * m)))
        F = np.fft.rfft(S, n=nfft, axis=0)
        # the circular cross-correlation of each pair i <= j, every lag at once: index l holds
        # C[l, i, j] = sum_t S[t + l, i] S[t, j], index nfft - l holds C[l, j, i] (no wrap: nfft >= 2m)
        c = np.fft.irfft(F[:, iu] * np.conj(F[:, ju]), n=nfft, axis=0)
        w = 1.0 - np.arange(1, L + 1) / (L + 1)
        C0, G = np.zeros((p, p)), np.zeros((p, p))
        C0[iu, ju] = C0[ju, iu] = c[0]
        G[iu, ju] = w @ c[1:L + 1]
        G[ju, iu] = w @ c[nfft - L:][::-1]
        omega += C0 + G + G.T
        a += m
    return 0.5 * (omega + omega.T)


@dataclass(frozen=True, eq=False)
class Covariance:
    """The covariance of a least-squares estimate (``covariance``'s result)."""

    matrix: np.ndarray  #: p x p in the fitting coordinates; rows/columns of unidentified parameters are inf
    identified: np.ndarray  #: per parameter: True when the data determine it
    singular_values: np.ndarray  #: of the scaled Jacobian, largest first

    @property
    def sd(self) -> np.ndarray:
        """Standard deviations (inf where not identified)."""
        return np.sqrt(np.maximum(np.diag(self.matrix), 0.0))

    @property
    def correlation(self) -> np.ndarray:
        """Correlation matrix: symmetric, |entries| <= 1, 1 on the diagonal; NaN in the
        rows and columns of unidentified parameters and of parameters with zero variance."""
        sd = self.sd
        ok = np.isfinite(sd) & (sd > 0)
        out = np.full(self.matrix.shape, np.nan)
        if ok.any():
            sub = self.matrix[np.ix_(ok, ok)] / np.outer(sd[ok], sd[ok])
            out[np.ix_(ok, ok)] = np.clip(0.5 * (sub + sub.T), -1.0, 1.0)
        out[np.diag_indices_from(out)] = np.where(ok, 1.0, np.nan)
        return out

    def block(self, n: int) -> Covariance:
        """The first n parameters (nuisance parameters after them marginalised out)."""
        return Covariance(self.matrix[:n, :n], self.identified[:n], self.singular_values)


def covariance(J: ArrayLike, r: ArrayLike, scale: ArrayLike | None = None,
               lengths: list[int] | None = None) -> Covariance:
    """HAC sandwich covariance of a least-squares estimate (see the module docstring).

    Args:
        J: n x p Jacobian of the residuals in the fitting coordinates.
        r: the n residuals at the estimate.
        scale: the p parameter scales D (default 1): J is taken as J D, the result scaled back.
        lengths: lengths of the series stacked in r, in order (default one series).
    """
    J = np.asarray(J, dtype=float)
    r = np.asarray(r, dtype=float)
    if J.ndim != 2 or r.shape != (J.shape[0],):
        raise ValueError(f"invalid Jacobian shape = {J.shape}: must be (n, p) with n = len(r) = {r.size}")
    n, p = J.shape
    lengths = [n] if lengths is None else [int(m) for m in lengths]
    if sum(lengths) != n:
        raise ValueError(f"invalid lengths: they sum to {sum(lengths)}, the residual has {n} samples")
    D = np.ones(p) if scale is None else np.maximum(np.abs(np.asarray(scale, dtype=float)), 1e-300)
    if D.shape != (p,):
        raise ValueError(f"invalid scale shape = {D.shape}: expected ({p},)")
    Js = J * D
    if not np.all(np.isfinite(Js)):
        return Covariance(np.full((p, p), np.inf), np.zeros(p, bool), np.full(min(n, p), np.nan))
    R = np.linalg.qr(Js, mode="r")  # the SVD of the small R (min(n, p) x p) is the SVD of Js
    _, s, Vt = np.linalg.svd(R, full_matrices=True)
    V = Vt.T
    keep = np.zeros(p, bool)
    if s.size and s[0] > 0:
        keep[: s.size] = s > RCOND * s[0]
    identified = ~np.any(np.abs(V[:, ~keep]) >= NULL_LOADING, axis=1)
    B = (V[:, keep] / s[keep[: s.size]] ** 2) @ V[:, keep].T
    omega = long_run_covariance(Js, r, lengths)
    cov = D[:, None] * (B @ omega @ B) * D[None, :]
    cov = 0.5 * (cov + cov.T)
    cov[~identified, :] = np.inf
    cov[:, ~identified] = np.inf
    return Covariance(cov, identified, s)


def noise_sigma(y: np.ndarray) -> float:
    """Noise standard deviation of a record channel from its third differences
    (robust MAD; smooth signal content sampled well above its bandwidth cancels)."""
    d3 = np.diff(y, 3)
    return float(1.4826 * np.median(np.abs(d3 - np.median(d3))) / math.sqrt(20.0))


__all__ = ["LEVEL", "NULL_LOADING", "RCOND", "Covariance", "ar1_coefficient", "ar1_effective_n", "noise_sigma",
           "bartlett_bandwidth", "covariance", "lag1_autocorrelation", "long_run_covariance", "quantile"]
