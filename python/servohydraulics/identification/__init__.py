"""Identification: rig keys from records by simulation-error least squares, with one
coordinates concept, one covariance rule and one record-simulation helper
(docs/lab-records.md; ``sh.diagnose`` fits its candidate effects with the same parts).

* :func:`identify` (``sh.identify``): two-stage identification of rig keys from lab records
  (``records.py``), never worse than its start (``fit.keep_best``).
* :mod:`.stats`: lag-1 autocorrelation, AR(1) effective samples and the HAC sandwich
  covariance (from an SVD; unidentified directions get infinite intervals).
* :mod:`.coordinates`: :class:`Coordinates` (log, linear or reciprocal per key) and the key tables.
* :mod:`.fit`: the frequency and time stages; :mod:`.run`: :func:`simulate_record` (a ``Response``).
* :mod:`.frf`: :class:`FrequencyResponse` from :func:`h1` or :func:`dft_ratio`.
* :func:`compare`, :func:`generic_rig`, :mod:`.baselines` (the thesis' models), :mod:`.report`, :mod:`.figures`.
* :mod:`.paper`: the paper-era fits (damping and friction, first order, free vibration).
"""

from .baselines import thesis_displacement, thesis_mr_force, thesis_mr_parameters
from .compare import Comparison, compare
from .coordinates import LOOP_KEYS, SPECIMEN_KEYS, Coordinates
from .frf import FrequencyResponse, dft_ratio, h1
from .generic import generic_rig
from .paper import *  # noqa: F403 (the paper-era fits, paper.__all__)
from .paper import __all__ as _paper_names
from .records import Identification, as_records, identify
from .run import nrmse_demeaned_pct, nrmse_pct, simulate_command, simulate_record
from .stats import Covariance, covariance

__all__ = ["LOOP_KEYS", "SPECIMEN_KEYS", "Comparison", "Coordinates", "Covariance", "FrequencyResponse",
           "Identification", "as_records", "compare", "covariance", "dft_ratio", "generic_rig", "h1", "identify",
           "nrmse_demeaned_pct", "nrmse_pct", "simulate_command", "simulate_record", "thesis_displacement",
           "thesis_mr_force", "thesis_mr_parameters", *_paper_names]
