"""Lab records: identify a rig from its own records, compare a rig with a record,
and the thesis baselines of the UTFSM records (docs/lab-records.md).

* :func:`identify` (``sh.identify``): two-stage identification of rig keys.
* :func:`compare`: a record's command through a rig, NRMSE and FRF per channel.
* :func:`generic_rig`: a documented start scaled from a record.
* :mod:`.baselines`: the thesis' linear G(s) and its Spencer Bouc-Wen MR-damper model.
* :func:`h1`: the H1 frequency response with coherence.
"""

from .baselines import thesis_displacement, thesis_mr_force, thesis_mr_parameters
from .compare import Comparison, compare
from .frf import FrequencyResponse, h1
from .generic import generic_rig
from .identification import Identification, identify
from .keys import LOOP_KEYS, SPECIMEN_KEYS
from .run import nrmse_demeaned_pct, nrmse_pct, simulate_record

__all__ = ["LOOP_KEYS", "SPECIMEN_KEYS", "Comparison", "FrequencyResponse", "Identification", "compare",
           "generic_rig", "h1", "identify", "nrmse_demeaned_pct", "nrmse_pct", "simulate_record",
           "thesis_displacement", "thesis_mr_force", "thesis_mr_parameters"]
