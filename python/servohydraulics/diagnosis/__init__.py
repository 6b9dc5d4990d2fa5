"""Diagnosis: find where simulation and measurement disagree, name the missing
physical effect from a library, fit it, add it to the model, show the gap shrink.

    import servohydraulics as sh
    d = sh.diagnose(["lab.csv"], sh.load_rig("nominal.toml"), mode="displacement")
    d.verdict, d.effects, d.gap_before, d.gap_after
    d.write("out")   # diagnosis.json, rig_updated.toml, report.md + plots

See docs/diagnose.md.
"""

from .effects import LIBRARY, NAMES, Candidate, Param, separating_experiment
from .types import CandidateLog, JointRefit
from .workflow import Diagnosis, diagnose

__all__ = ["LIBRARY", "NAMES", "Candidate", "CandidateLog", "Diagnosis", "JointRefit", "Param", "diagnose",
           "separating_experiment"]
