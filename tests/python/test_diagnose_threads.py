"""Diagnose on threads: the candidates of a round and the fits' difference columns run on two
threads (``workflow._each``, ``engine.workers``); the oracle is the same diagnosis run on one
thread, which must agree to the bit (the candidates are independent and scipy's
``least_squares(workers=...)`` computes the serial columns).  And the split of the runs: the
search at identify's tolerance, the decisions at the core's default, neither checked by the pair's
shadow (its flags are not read; the results are the same to the bit)."""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics.diagnosis import engine
from servohydraulics.identification import fit as idfit
from servohydraulics.identification.fit import FIT_RTOL
from servohydraulics.records import Record

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "evaluation" / "diagnose_eval"))
import independent_plant as ip  # noqa: E402

DT = 5e-4


def _record() -> Record:
    """2 s of displacement control with 300 N of Coulomb friction hidden (the independent simulator),
    30 dB of noise."""
    t = np.arange(int(2.0 / DT) + 1) * DT
    u = np.minimum(t / 0.25, 1) * (0.02 * np.sin(2 * np.pi * 0.8 * t) + 0.004 * np.sin(2 * np.pi * (1 + t) * t))
    ch = ip.simulate(replace(ip.Truth(), friction="coulomb", F_c=300.0), "displacement", u, DT, substeps=4)
    rng = np.random.default_rng(5)
    rec = {"time": ch["time"], "command": ch["command"]}
    for c in ("displacement", "force"):
        y = ch[c]
        rec[c] = y + rng.normal(0, float(np.sqrt(np.mean(y ** 2))) * 10 ** (-30 / 20), y.size)
    return Record({k: np.asarray(v) for k, v in rec.items()})


def _rig() -> sh.Rig:
    rig = sh.zhao2003()
    for e in ("coulomb_friction", "spring_softening", "load_pressure", "flow_nonlinearity"):
        setattr(rig.effects, e, False)
    return rig


def test_two_threads_give_the_one_threads_diagnosis(monkeypatch):
    rec, rig = _record(), _rig()
    two = sh.diagnose(rec, rig, mode="displacement", progress=False, max_effects=1)
    monkeypatch.setattr(idfit, "default_workers", lambda: 1)
    one = sh.diagnose(rec, rig, mode="displacement", progress=False, max_effects=1)
    a, b = two.to_dict(), one.to_dict()
    for d in (a, b):
        d.pop("runtime_s")
        for c in d["candidates"]:
            c.pop("fit_seconds", None)
    assert json.dumps(a, sort_keys=True, default=str) == json.dumps(b, sort_keys=True, default=str)
    assert two.effects and two.effects[0]["name"] == "coulomb_friction"


def test_search_and_decision_runs():
    search, decision = engine.run_options(True), engine.run_options(False)
    assert search.rtol == FIT_RTOL and decision.rtol == sh.solver_options().rtol
    assert not search.stiff_check and not decision.stiff_check
    assert search.method == decision.method == sh.solver_options().method
