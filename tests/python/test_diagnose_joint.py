"""Diagnose: the joint re-fit of two hidden effects.

The record is made by the independent plain-Python simulator of the evaluation
(evaluation/diagnose_eval/independent_plant.py, no code shared with the core the
workflow uses) with two effects hidden at known values, and measurement noise;
the workflow sees only the record, the mode and the nominal rig.  Fitted one
after the other, the first effect's parameter absorbs part of the second (a
command delay takes up part of a missing viscous damping), so both greedy
values are biased and their 95 % intervals miss the truth; the joint re-fit of
both must bring both within a few per cent of the truth with intervals that
cover it.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics.records import Record

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "evaluation" / "diagnose_eval"))
import independent_plant as ip  # noqa: E402

DT = 5e-4  #: 2 kHz [s]
C_TRUE = 6000.0  #: hidden viscous damping [N s/m] (the nominal model has 2.1 kN s/m)
TAU_TRUE = 0.005  #: hidden pure delay of the command [s]


def _nominal() -> sh.Rig:
    """The model the workflow is told to believe (as the evaluation's): the
    preset with the nonlinear effects of the paper's linear analysis off."""
    rig = sh.zhao2003()
    for e in ("coulomb_friction", "spring_softening", "load_pressure", "flow_nonlinearity"):
        setattr(rig.effects, e, False)
    return rig


def _record(snr_db: float = 40.0, seed: int = 37, duration: float = 3.0) -> Record:
    """A displacement-controlled test (3.2 cm sine near 0.5 Hz plus a 4 mm chirp, as
    the evaluation's records) of a rig with c = 6 kN s/m and a 5 ms command delay,
    with white noise on displacement and force at ``snr_db``."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(duration / DT)) + 1) * DT
    ph = rng.uniform(0, 2 * np.pi, 2)
    u = np.minimum(t / 0.25, 1.0) * (0.032 * np.sin(2 * np.pi * 0.5 * t + ph[0])
                                     + 0.004 * np.sin(2 * np.pi * (1 + 0.8 * t) * t + ph[1]))
    truth = replace(ip.Truth(), c=C_TRUE, delay="pure", tau=TAU_TRUE)
    ch = ip.simulate(truth, "displacement", u, DT, substeps=4)
    rec = {"time": ch["time"], "command": ch["command"]}
    for c in ("displacement", "force"):
        y = ch[c]
        rec[c] = y + rng.normal(0.0, float(np.sqrt(np.mean(y ** 2))) * 10 ** (-snr_db / 20), y.size)
    return Record(rec)


def _covers(p: dict, truth: float) -> bool:
    lo, hi = p["interval_95"]
    return lo is not None and hi is not None and lo <= truth <= hi


def test_joint_refit_recovers_viscous_damping_and_delay() -> None:
    d = sh.diagnose(_record(), _nominal(), mode="displacement", progress=False)
    names = [e["name"] for e in d.effects]
    assert d.verdict == "effect_found", d.summary
    assert sorted(names) == ["command_delay", "viscous_damping"], names  # only the two hidden effects
    jr = d.to_dict()["joint_refit"]
    assert jr and jr[-1]["kept"], jr
    last = jr[-1]
    assert sorted(last["effects"]) == ["command_delay", "viscous_damping"]
    assert last["bic_joint"] <= last["bic_greedy"]

    # the greedy fits (one effect at a time) are biased: at least one interval misses its truth
    greedy = last["parameters_greedy"]
    g_c, g_tau = greedy["viscous_damping"]["c"], greedy["command_delay"]["command_delay"]
    assert not (_covers(g_c, C_TRUE) and _covers(g_tau, TAU_TRUE)), (g_c, g_tau)

    # the joint re-fit: both within a few per cent of truth, both intervals cover it
    c = d.effects[names.index("viscous_damping")]["parameters"]["c"]
    tau = d.effects[names.index("command_delay")]["parameters"]["command_delay"]
    assert abs(c["value"] - C_TRUE) < 0.03 * C_TRUE, c
    assert abs(tau["value"] - TAU_TRUE) < 0.02 * TAU_TRUE, tau
    assert _covers(c, C_TRUE), c
    assert _covers(tau, TAU_TRUE), tau
    # and they are closer to the truth than the greedy ones
    assert abs(c["value"] - C_TRUE) < abs(g_c["value"] - C_TRUE)
    assert abs(tau["value"] - TAU_TRUE) < abs(g_tau["value"] - TAU_TRUE)

    # the model carries the joint values, and the gap reported is the joint model's
    assert d.rig.c == c["value"]
    assert d.command_delay == tau["value"]
    assert d.rig.command_delay == tau["value"]  # a real rig parameter now: rig_updated.toml carries it
    assert d.gap_after["force"] <= last["gap_greedy"]["force"]
    assert d.plots["history"][-1][0] == "joint re-fit"
