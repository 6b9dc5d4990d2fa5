"""``servohydraulics demo``: kept importable; the demo lives in :mod:`servohydraulics.paper.demo`."""

from .paper.demo import run_demo

__all__ = ["run_demo"]
