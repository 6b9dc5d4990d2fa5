"""Property tests of the FMUs through fmpy (issue 26, docs/robustness.md): drawn
start times, parameters set before initialisation, inputs and communication
steps.  Every call ends in ``fmi2OK`` with finite outputs, or ``fmi2Error`` with
a logged message (an ``FMICallException`` in fmpy); never a crash, a hang (a
step is bounded by ``fmu::kMaxSamplesPerStep``), or an ``fmi2OK`` with a
non-finite output.  A plant started at a drawn start time gives the outputs of
one started at 0."""

from __future__ import annotations

import math
import time

import pytest
from fuzz_support import Tally, counted
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import servohydraulics as sh

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmu_support import instantiate  # noqa: E402

OUTCOMES = Tally()
DT = 5e-4
#: Wall-time bound of one drawn case (a few steps of at most 400 samples each) [s].
BOUND_S = 20.0
HOSTILE = [0.0, -1.0, math.nan, math.inf, -math.inf, 1e300, -1e300, 5e-16, 1e-300]


def teardown_module() -> None:
    OUTCOMES.report(__name__)


@pytest.fixture(scope="module")
def units(tmp_path_factory):
    """The plant and both controllers, exported and extracted once."""
    d = tmp_path_factory.mktemp("fuzz_fmus")
    rig = sh.zhao2003()
    out = {}
    for kind in ("plant", "eft", "rpsd"):
        path = sh.export_fmu(rig, d / f"{kind}.fmu", kind=kind)
        folder = extract(str(path), unzipdir=str(d / kind))
        out[kind] = (folder, read_model_description(folder))
    return out


class Instance:
    def __init__(self, folder, md, logs):
        self.var = {v.name: v for v in md.modelVariables}
        self.fmu, self._cb = instantiate(folder, md, "fuzz", logs)

    def set(self, name, value):
        v = self.var[name]
        if v.type == "Real":
            self.fmu.setReal([v.valueReference], [value])
        elif v.type == "Boolean":
            self.fmu.setBoolean([v.valueReference], [bool(value) if math.isfinite(value) else True])
        else:
            self.fmu.setInteger([v.valueReference], [int(max(-2**31, min(2**31 - 1, value)))
                                                     if math.isfinite(value) else -1])

    def outputs(self):
        names = [n for n, v in self.var.items() if v.causality == "output" and v.type == "Real"]
        return dict(zip(names, self.fmu.getReal([self.var[n].valueReference for n in names])))


VALUES = st.one_of(st.sampled_from(HOSTILE), st.floats(-1e3, 1e3), st.floats(-0.01, 0.01))


def _call(logs, f, *args, **kwargs) -> bool:
    """True when the call returned fmi2OK; an fmi2Error must have logged a message."""
    n = len(logs)
    try:
        f(*args, **kwargs)
        return True
    except FMICallException:
        assert len(logs) > n and logs[-1].strip(), "an fmi2Error without a message"
        return False


@settings(max_examples=120, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(kind=st.sampled_from(["plant", "eft", "rpsd"]),
       start=st.one_of(st.sampled_from([0.0, 1.7e9, 1e10, math.nan, math.inf, -5.0]), st.floats(-1e3, 1e3)),
       params=st.lists(st.tuples(st.integers(0, 10**6), VALUES), max_size=3),
       steps=st.lists(st.tuples(st.sampled_from([1, 2, 7, 400, 0.5, 1e9, -1, math.nan, math.inf]),
                                st.lists(st.tuples(st.integers(0, 10**6), VALUES), max_size=2)),
                      min_size=1, max_size=6))
@counted(OUTCOMES)
def test_fmu_calls(units, kind, start, params, steps):
    folder, md = units[kind]
    logs: list[str] = []
    s = Instance(folder, md, logs)
    tunable = [n for n, v in s.var.items() if v.causality == "parameter"]
    inputs = [n for n, v in s.var.items() if v.causality == "input"]
    t0 = time.monotonic()
    try:
        if not _call(logs, s.fmu.setupExperiment, startTime=start):
            OUTCOMES["error: setup"] += 1
            assert not math.isfinite(start)
            return
        assert math.isfinite(start), "a non-finite start time accepted"
        s.fmu.enterInitializationMode()
        for i, value in params:
            _call(logs, s.set, tunable[i % len(tunable)], value)
        if not _call(logs, s.fmu.exitInitializationMode):
            OUTCOMES["error: initialisation"] += 1
            return
        t = start
        for samples, sets in steps:
            for i, value in sets:
                _call(logs, s.set, inputs[i % len(inputs)], value)
            h = samples * float(s.fmu.getReal([s.var["dt"].valueReference])[0])
            if _call(logs, s.fmu.doStep, currentCommunicationPoint=t, communicationStepSize=h):
                OUTCOMES["ok: step"] += 1
                t += h
                bad = {n: v for n, v in s.outputs().items() if not math.isfinite(v)}
                assert not bad, f"fmi2OK with non-finite outputs {bad}"
            else:
                OUTCOMES["error: step"] += 1
        assert time.monotonic() - t0 < BOUND_S
    finally:
        s.fmu.terminate()
        s.fmu.freeInstance()


@settings(max_examples=20, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(start=st.one_of(st.sampled_from([1.7e9, 1e10, 3.1e7]), st.floats(-1e9, 1e11)),
       amplitude=st.floats(-0.005, 0.005))
@counted(OUTCOMES)
def test_plant_fmu_output_does_not_depend_on_the_start_time(units, start, amplitude):
    folder, md = units["plant"]
    runs = []
    for t_start in (0.0, start):
        s = Instance(folder, md, [])
        s.fmu.setupExperiment(startTime=t_start)
        s.fmu.enterInitializationMode()
        s.fmu.exitInitializationMode()
        rows = []
        for k in range(100):
            s.set("command", amplitude * math.sin(2 * math.pi * 5 * k * DT))
            s.fmu.doStep(currentCommunicationPoint=t_start + k * DT, communicationStepSize=DT)
            rows.append(s.outputs())
        s.fmu.terminate()
        s.fmu.freeInstance()
        runs.append(rows)
    assert runs[0] == runs[1]
