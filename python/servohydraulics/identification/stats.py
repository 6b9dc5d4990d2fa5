"""Statistics of a simulation-error least-squares fit: lag-1 autocorrelation, the
AR(1) effective sample size, and the one covariance estimator every fit of the
package uses (``sh.identify``, ``sh.diagnose``).

**The covariance rule: a HAC (Newey-West) sandwich, computed from an SVD.**

    cov = D (J_s' J_s)^+ Omega (J_s' J_s)^+ D,   J_s = J D,

with J the Jacobian of the stacked residuals r in the fitting coordinates, D the
parameters' scales (columns differ by ten orders of magnitude), and Omega the
long-run covariance of the scores J_s,t r_t, prewhitened by an AR(1) per parameter and
recoloured (after Andrews and Monahan 1992) around Bartlett weights, summed over the series (record,
channel) the residual stacks (no lag crosses two series), the lag truncation per
series from the AR(1) plug-in rule of Andrews (1991).

Why this one.  The residual of a simulation-error fit is autocorrelated (model
error, coloured noise, a response that integrates the noise).  The alternative
the package had, s^2 (J'J)^-1 inflated by n / n_eff(AR(1)), assumes one AR(1)
for the whole residual and the same correction for every parameter; the sandwich
weights the autocorrelation by each parameter's own score series, so a key the
slow drift loads on gets the wider interval and one the fast content determines
does not.  It needs no noise model, reduces to s^2 (J'J)^-1 for white residuals,
and stays valid for weighted residuals (the channel weights of ``sh.identify``).
The scores are prewhitened by an AR(1) per parameter before the Bartlett sum and recoloured after it
(Andrews and Monahan 1992): the Bartlett kernel alone is biased low for persistent residuals
(a regression on AR(1) noise with phi = 0.95: 95 % intervals covered 84-88 %, prewhitened
91-93 %; phi = 0.6: 92 %, prewhitened 94-95 %, ``test_uncertainty_report.py``); against an
AR(1) mean it recovers the long-run variance within 15 % (``test_identification.py``).  The
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


#: the prewhitening AR(1) coefficients are capped here (Andrews and Monahan 1992): I - A stays
#: invertible and a near-unit-root fit cannot blow the recoloured covariance up
PREWHITEN_CAP = 0.97


def _bartlett(S: np.ndarray, L: int) -> np.ndarray:
    """sum_{|l| <= L} (1 - |l| / (L + 1)) Gamma_l of the rows of S (Gamma_l = sum_t S_{t+l} S_t').

    As Gamma_0 + G + G' with G = sum_{l=1..L} w_l Gamma_l = Y' S, where Y_t = sum_{l=1..L} w_l S_{t+l}
    is each column of S filtered by the triangular weights (one overlap-add convolution per column):
    p convolutions and one product instead of a cross-correlation of each of the p (p + 1) / 2 pairs."""
    from scipy.signal import oaconvolve

    m, p = S.shape
    C0 = S.T @ S
    L = int(min(max(L, 0), m - 1))
    if L == 0:
        return C0
    w = 1.0 - np.arange(1, L + 1) / (L + 1)
    full = oaconvolve(S, w[::-1, None], mode="full", axes=0)  # full[n] = sum_l w_l S[n - L + l]
    Y = np.zeros_like(S)
    Y[:-1] = full[L:m + L - 1]
    G = Y.T @ S
    return C0 + G + G.T


def prewhitening_matrix(S: np.ndarray) -> np.ndarray:
    """The prewhitening coefficients of the score series, S_i,t = a_i S_i,t-1 + u_i,t per parameter
    (each its own least-squares AR(1), clipped to [0, ``PREWHITEN_CAP``]), as the diagonal matrix A.
    Per parameter, not a full VAR(1): a nuisance score that is a short transient (a record's
    initial displacement) would otherwise leak into every other parameter's recoloured variance."""
    num = np.einsum("ti,ti->i", S[1:], S[:-1])
    den = np.einsum("ti,ti->i", S[:-1], S[:-1])
    a = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return np.diag(np.clip(a, 0.0, PREWHITEN_CAP))


def long_run_covariance(scores: np.ndarray, r: np.ndarray, lengths: list[int]) -> np.ndarray:
    """Omega = sum over series of the long-run covariance of the scores S_t = scores_t r_t,
    prewhitened (after Andrews and Monahan 1992): S_t = A S_t-1 + u_t with A the per-parameter
    AR(1) coefficients (``prewhitening_matrix``), the Bartlett-weighted autocovariances of u up to the
    ``bartlett_bandwidth`` of the prewhitened residual r_t - rho r_t-1 are summed, and the result
    is recoloured, (I - A)^-1 Omega_u (I - A)^-T (symmetric).  Why prewhiten: the Bartlett kernel
    down-weights the lags it keeps, so for a persistent residual the plain estimator is low (AR(1)
    scores with phi = 0.95: 95 % intervals covered 84-88 %; prewhitened 91-93 %,
    ``test_uncertainty_report.py``)."""
    p = scores.shape[1]
    omega = np.zeros((p, p))
    a = 0
    for m in lengths:
        S = scores[a:a + m] * r[a:a + m, None]
        e = r[a:a + m]
        A = prewhitening_matrix(S)
        u = S[1:] - S[:-1] @ A.T
        L = bartlett_bandwidth(e[1:] - ar1_coefficient(e) * e[:-1]) if m > 2 else 1
        B = np.linalg.inv(np.eye(p) - A)
        omega += B @ _bartlett(u, L) @ B.T
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


# --- what a report says about each parameter ------------------------------------------------
#
# Shared by ``sh.identify``'s report and ``sh.diagnose``'s: every fitted parameter has a status,
# the parameters are listed from the best determined to the worst, and parameters the records
# cannot tell apart are grouped.

#: |correlation| above which two parameters are reported as not separable by the records
MAX_CORRELATION = 0.95
#: the statuses of a fitted parameter, and what a report says for each
STATUS_WORDS = {"identified": "identified", "at bound": "at bound / not identified",
                "not identified": "not identified"}


def bound_status(z: ArrayLike, lo: ArrayLike, hi: ArrayLike, identified: ArrayLike,
                 tol: float = 1e-6, scale: ArrayLike | None = None) -> list[str]:
    """Per parameter: "at bound" when its estimate z is within ``tol`` times its ``scale`` (default:
    the larger of 1 and |z|) of a bound of its fitting range [lo, hi] (a parameter that collapsed
    to a limit of its range: its sandwich interval, from a one-sided Jacobian, would be falsely
    precise), else "not identified" where ``identified`` is False (``Covariance``), else
    "identified"."""
    z, lo, hi = (np.asarray(a, dtype=float) for a in (z, lo, hi))
    ok = np.asarray(identified, dtype=bool)
    size = np.maximum(1.0, np.where(np.isfinite(z), np.abs(z), 1.0)) if scale is None else np.abs(
        np.asarray(scale, dtype=float))
    t = tol * size
    at = (np.isfinite(lo) & (z - lo <= t)) | (np.isfinite(hi) & (hi - z <= t))
    return ["at bound" if a else ("identified" if o else "not identified") for a, o in zip(at, ok)]


def inseparable_groups(correlation: ArrayLike, threshold: float = MAX_CORRELATION) -> list[list[int]]:
    """Groups (two or more parameters, as index lists in order) that the records cannot tell apart:
    the connected components of the graph whose edges are the pairs with |correlation| > ``threshold``
    (NaN entries, those of parameters without a finite variance, link nothing)."""
    c = np.nan_to_num(np.abs(np.asarray(correlation, dtype=float)), nan=0.0)
    n = c.shape[0]
    seen, groups = set(), []
    for i in range(n):
        if i in seen:
            continue
        comp, todo = {i}, [i]
        while todo:
            a = todo.pop()
            for b in np.flatnonzero(c[a] > threshold):
                if int(b) != a and int(b) not in comp:
                    comp.add(int(b))
                    todo.append(int(b))
        seen |= comp
        if len(comp) > 1:
            groups.append(sorted(comp))
    return groups


def precision_order(relative_sd: ArrayLike, status: list[str] | None = None) -> list[int]:
    """Indices from the best determined parameter to the worst: "identified" ones by their relative
    standard error (sd / |value|) ascending, then those at a bound, then those not identified
    (stable within each)."""
    r = np.asarray(relative_sd, dtype=float)
    status = status or ["identified"] * r.size
    rank = {"identified": 0, "at bound": 1, "not identified": 2}
    key = [(rank.get(s, 2), v if np.isfinite(v) else np.inf, i) for i, (s, v) in enumerate(zip(status, r))]
    return [i for *_, i in sorted(key)]


def noise_sigma(y: np.ndarray) -> float:
    """Noise standard deviation of a record channel from its third differences
    (robust MAD; smooth signal content sampled well above its bandwidth cancels)."""
    d3 = np.diff(y, 3)
    return float(1.4826 * np.median(np.abs(d3 - np.median(d3))) / math.sqrt(20.0))


__all__ = ["LEVEL", "MAX_CORRELATION", "NULL_LOADING", "RCOND", "STATUS_WORDS", "Covariance", "ar1_coefficient",
           "ar1_effective_n", "bartlett_bandwidth", "bound_status", "covariance", "inseparable_groups",
           "lag1_autocorrelation", "long_run_covariance", "noise_sigma", "precision_order", "prewhitening_matrix",
           "quantile"]
