"""Records of the diagnosis evaluation's independent simulator for the diagnosis tests.

``evaluation/diagnose_eval/independent_plant.py`` (plain-Python RK4 of Eqs 1-5, no code shared
with the core) driven by the evaluation's standard command (``generate.command``), with the
effects of ``truth`` hidden in it and white noise on displacement and force.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from servohydraulics.records import Record

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "evaluation" / "diagnose_eval"))
import generate as gen  # noqa: E402
import independent_plant as ip  # noqa: E402

#: the records' time step [s] (2 kHz)
DT = 5e-4


def independent_record(mode: str = "displacement", rig: str = "paper", duration: float = 4.0, seed: int = 3,
                       snr: float = 30, scale: float = 1.0, noise_seed: int | None = None, **truth) -> Record:
    """A ``duration`` s record of ``rig`` in ``mode`` with ``truth`` hidden: the evaluation's command
    (times ``scale``; drawn from ``default_rng(seed)``), white noise at ``snr`` dB on displacement and
    force, drawn from ``default_rng(noise_seed)``, or from the command's generator after it when
    ``noise_seed`` is None."""
    rng = np.random.default_rng(seed)
    u, _ = gen.command(mode, "std", duration, rng)
    u = u * gen.RIGS[rig][1 if mode == "displacement" else 2] * scale
    ch = ip.simulate(replace(gen.base_truth(mode, rig), **truth), mode, u, DT, substeps=4)
    noise = rng if noise_seed is None else np.random.default_rng(noise_seed)
    rec = {"time": ch["time"], "command": ch["command"]}
    for c in ("displacement", "force"):
        y = ch[c]
        rec[c] = y + noise.normal(0.0, float(np.sqrt(np.mean(y ** 2))) * 10 ** (-snr / 20), y.size)
    return Record(rec)
