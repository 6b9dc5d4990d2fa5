"""``servohydraulics reproduce``: kept importable; the reproduction lives in
:mod:`servohydraulics.paper` (claims, experiments, evaluation, figures, report, driver)."""

from .paper.evaluate import Row
from .paper.report import Reproduction
from .paper.reproduce import SECTIONS, reproduce

__all__ = ["Reproduction", "Row", "SECTIONS", "reproduce"]
