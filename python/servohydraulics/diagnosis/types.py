"""Typed records of the diagnosis: a record prepared for comparison (``Case``),
the screening of a candidate (``Screening``), a least-squares fit by simulation
error (``FitResult``), a candidate confirmed by its fits (``Fit``), an accepted
effect's fitted block (``Accepted``), the JSON row of a candidate
(``CandidateLog``), a joint re-fit (``JointRefit``) and the outcome of one round
(``Round``).

All are frozen: a step of the workflow returns new records instead of changing
the ones it was given.  Arrays are not compared (``eq=False``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Optional

import numpy as np

from ..rig import Rig

#: one simulation: channel -> samples (None when the run failed)
Sim = Optional[dict]


@dataclass(frozen=True, eq=False)
class Case:
    """One record prepared for simulation and comparison.  The initial
    displacement used in a simulation is passed explicitly (the workflow keeps
    the fitted ones); ``x0_data`` is the estimate from the record alone."""

    name: str
    mode: str
    dt: float
    t: np.ndarray  #: time from 0 [s]
    u: np.ndarray  #: the record's command [m or N]
    meas: dict  #: channel -> measured samples (SI)
    scale: dict  #: channel -> rms of the measured channel (normalisation)
    sigma: dict  #: channel -> noise standard deviation estimated from the record itself
    train: np.ndarray  #: boolean mask of the training samples
    derived: dict  #: measured velocity/acceleration (Savitzky-Golay when not recorded)
    x0_data: float = 0.0  #: initial displacement estimated from the record alone [m]
    x0_sd: float = 0.0  #: its standard deviation [m]
    v_peak: float = 1.0  #: largest |velocity| of the record (measured or derived) [m/s]
    controller_dt: float | None = None  #: the controller's sample time [s] (None: the record's ``dt``)

    @property
    def channels(self) -> tuple[str, ...]:
        return tuple(self.meas)


@dataclass(frozen=True, eq=False)
class Screening:
    """A candidate's secant screen: the share of the current residual its
    signature explains, the implied start of the fit (fitting coordinates) and
    the signature itself (stacked normalised channels)."""

    score: float
    z0: np.ndarray
    signature: np.ndarray | None
    failed: bool = False


@dataclass(frozen=True, eq=False)
class FitResult:
    """A bounded least-squares fit by simulation error (``engine.fit``)."""

    z: np.ndarray  #: the fitted parameters (fitting coordinates)
    x0: np.ndarray  #: each record's co-fitted initial displacement [m]
    jac: np.ndarray  #: Jacobian of the normalised residuals, columns of z then of x0
    fun: np.ndarray  #: the normalised residuals at the solution
    nuisance_scale: np.ndarray  #: the x0 columns' scale (their standard deviations) [m]
    nfev: int


@dataclass(frozen=True)
class Refit:
    """The bounded re-fit of a candidate's interacting nominal parameters."""

    tried: bool = False
    kept: bool = False
    parameters: tuple[str, ...] = ()
    delta_bic_with: float | None = None
    delta_bic_without: float | None = None

    def to_dict(self) -> dict[str, Any]:
        if not self.tried:
            return {"tried": False, "kept": False}
        return {"tried": True, "kept": self.kept, "parameters": list(self.parameters),
                "delta_bic_with": self.delta_bic_with, "delta_bic_without": self.delta_bic_without}


@dataclass(frozen=True, eq=False)
class Fit:
    """A candidate confirmed by simulation-error fits (``confirm``): its
    parameter space, values, 95 % intervals, the model it makes and the tests
    the acceptance rules read."""

    space: Any  #: ``engine.Space`` of the kept fit (with or without the interacting re-fit)
    z: np.ndarray  #: fitted on all data (fitting coordinates)
    z_tr: np.ndarray  #: fitted on the training segments
    lo: np.ndarray  #: 95 % interval (fitting coordinates)
    hi: np.ndarray
    rig: Rig  #: the model with the effect at z
    tau: float  #: its command delay [s]
    x0: np.ndarray  #: the fit's initial displacements [m]
    joint_excludes: bool  #: the joint 95 % region of the tested parameters excludes "absent"
    joint_p: float
    sims: list  #: the model's simulations of the records
    stats: dict  #: ``engine.channel_stats`` of them
    neff: dict  #: effective sample sizes for the BIC
    dbic: float  #: BIC improvement over the current model
    held: float  #: held-out SSR improvement (fraction)
    held_lr: float  #: held-out -2 log likelihood improvement
    refit: Refit = field(default_factory=Refit)
    #: the fit ended worse than "absent" and was replaced by it (the invariant of ``confirm.fit_space``)
    ended_at_absent: bool = False
    corr: np.ndarray | None = None  #: the parameters' correlation matrix (NaN where a variance is infinite or zero)


@dataclass(frozen=True, eq=False)
class Accepted:
    """An accepted effect's fitted block, kept for the joint re-fit."""

    name: str
    space: Any  #: its ``engine.Space``
    z: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    corr: np.ndarray | None = None  #: the parameters' correlation matrix


@dataclass(frozen=True)
class CandidateLog:
    """One candidate in one round: a row of diagnosis.json's ``candidates``.
    The confirmation fields are written only for candidates that were fitted."""

    name: str
    round: int
    screening_score: float | None = None
    balance_score: float | None = None
    score: float | None = None
    delta_bic: float | None = None
    heldout_improvement: float | None = None
    parameters: dict | None = None
    accepted: bool = False
    rejection: str | None = None
    joint_p_absent: float | None = None
    refit: Refit | None = None
    fit_seconds: float | None = None
    heldout_lr: float | None = None
    fit_gap_to_runner_up: float | None = None
    #: the largest share of the nominal model's gap above the noise floor the candidate's fit closes on one
    #: channel (``engine.share_closed``; the materiality test)
    share_closed: float | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in _OPTIONAL_KEYS and v is None:
                continue
            out[f.name] = v.to_dict() if isinstance(v, Refit) else v
        return out


#: CandidateLog keys present only once set (a fitted candidate; the best of several passing ones)
_OPTIONAL_KEYS = ("joint_p_absent", "refit", "fit_seconds", "heldout_lr", "fit_gap_to_runner_up", "share_closed")


@dataclass(frozen=True)
class JointRefit:
    """The joint re-fit of the accepted effects after a round (a row of
    diagnosis.json's ``joint_refit``); fields that do not apply are left out."""

    round: int
    effects: tuple[str, ...]
    kept: bool = False
    superseded: tuple[str, ...] | None = None
    reason: str | None = None
    parameters_fitted: tuple[str, ...] | None = None
    nfev: int | None = None
    bic_greedy: float | None = None
    bic_joint: float | None = None
    delta_bic: float | None = None
    gap_greedy: dict | None = None
    gap_joint: dict | None = None
    parameters_greedy: dict | None = None
    parameters_joint: dict | None = None
    excludes_absent_joint: dict | None = None
    seconds: float | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if v is not None:
                out[f.name] = list(v) if isinstance(v, tuple) else v
        return out


@dataclass(frozen=True, eq=False)
class Round:
    """The outcome of one round: ``"accept"`` (``best`` is added), ``"ambiguous"``
    (two candidates explain the records equally well) or ``"stop"`` (none passed)."""

    number: int
    outcome: str
    log: tuple[CandidateLog, ...]
    best: Fit | None = None
    best_name: str = ""
    signature: np.ndarray | None = None  #: the best candidate's screening signature
    summary: str = ""
    ambiguous_between: tuple[str, ...] = ()
    separating_experiment: str = ""
