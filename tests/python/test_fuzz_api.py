"""Property tests of the Python API with hypothesis (docs/robustness.md): rig
parameters, commands, dt, solver options and the flow curve, drawn valid and
hostile.  Every input must end in one of
  - a result whose every channel is finite (success), or
  - a ValueError whose message names the field and the value ("invalid <field> = <value>: ..."),
    or, for a valid but extreme rig, the setup step that failed, its time and SUNDIALS' flag, or
  - a SimulationError naming the time of the failure, carrying the rows so far,
never another exception type, a crash, NaN in a successful result, or a run
past the stated bound (RUN_BOUND_S of wall time for 200 samples).
"""

from __future__ import annotations

import math
import re
import time

import numpy as np
import pytest
from fuzz_support import Tally, counted
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import servohydraulics as sh
from servohydraulics import _core

#: Wall-time bound of one 200-sample run [s]: CVODE is capped at max_steps_per_sample
#: internal steps per sample (2000) and RK4 at its substep rule; on a loaded CI core
#: a 200-sample run takes well under a second.
RUN_BOUND_S = 30.0
N = 200
FUZZ = settings(max_examples=600, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)

#: "invalid <field> = <value>: <requirement>"; the field may be dotted, indexed or a product.  A valid
#: but extreme rig may instead fail the integrator's setup, which names the step, the time and the flag.
NAMED = re.compile(r"invalid [A-Za-z_][\w.\[\]() ]* = [^:]+: \S|setup: .* failed at t = \S+ s: \w+ returned flag")

BAD = [0.0, -1.0, math.nan, math.inf, -math.inf, 1e308, -1e-300]
KEYS = [p.key for p in sh.PARAMETERS]


def factor() -> st.SearchStrategy[float]:
    """A multiplier of a preset value: mostly moderate (0.1x..10x), sometimes extreme."""
    return st.one_of(st.floats(0.1, 10.0), st.floats(1e-6, 1e6), st.sampled_from([1.0]))


@st.composite
def rigs(draw) -> tuple[sh.Rig, list[str]]:
    """The preset with a few parameters scaled or set to hostile values; returns (rig, changed keys)."""
    rig = sh.zhao2003()
    keys = draw(st.lists(st.sampled_from(KEYS), min_size=1, max_size=4, unique=True))
    for key in keys:
        base = getattr(rig, key)
        value = draw(st.one_of(factor().map(lambda f, b=base: (b if b else 1.0) * f), st.sampled_from(BAD)))
        setattr(rig, key, value)
    for name in draw(st.lists(st.sampled_from(list(sh.rig.EFFECTS)), max_size=3, unique=True)):
        setattr(rig.effects, name, not getattr(rig.effects, name))
    return rig, keys


def commands(mode: str) -> st.SearchStrategy[np.ndarray]:
    scale = {"displacement": 0.01, "force": 5e4, "free": 1e3}[mode]
    shapes = st.sampled_from(["sine", "step", "noise", "zero", "huge", "nan"])

    def build(shape: str, amp: float, seed: int) -> np.ndarray:
        t = np.arange(N) * 5e-4
        if shape == "sine":
            return amp * scale * np.sin(2 * np.pi * 5 * t)
        if shape == "step":
            return np.where(t > 0.01, amp * scale, 0.0)
        if shape == "noise":
            return amp * scale * np.random.default_rng(seed).standard_normal(N)
        if shape == "huge":
            return np.full(N, 1e300)
        if shape == "nan":
            u = np.zeros(N)
            u[seed % N] = math.nan
            return u
        return np.zeros(N)

    return st.builds(build, shapes, st.floats(0.0, 20.0), st.integers(0, 10_000))


OUTCOMES = Tally()


def teardown_module() -> None:
    OUTCOMES.report(__name__)


def check_outcome(run) -> str:
    """Runs run(); returns "ok", "value_error" or "simulation_error" if the outcome is allowed."""
    outcome = _check_outcome(run)
    OUTCOMES[outcome] += 1
    return outcome


def _check_outcome(run) -> str:
    t0 = time.perf_counter()
    try:
        res = run()
    except ValueError as e:
        assert NAMED.search(str(e)), f"ValueError does not name the field and value: {e}"
        return "value_error"
    except sh.SimulationError as e:
        assert re.search(r"t = [-+0-9.e]+ s", str(e)), f"SimulationError without the time: {e}"
        assert not e.partial.success and len(e.partial) >= 1
        return "simulation_error"
    finally:
        assert time.perf_counter() - t0 < RUN_BOUND_S
    assert res.success
    for name, v in res.channels.items():
        assert np.all(np.isfinite(np.asarray(v, dtype=float))), f"non-finite {name} in a successful result"
    return "ok"


@FUZZ
@given(rig=rigs(), mode=st.sampled_from(["displacement", "force", "free"]),
       method=st.sampled_from(["cvode", "rk4"]), data=st.data())
@counted(OUTCOMES)
def test_random_rigs_and_commands_end_in_a_result_or_a_named_error(rig, mode, method, data):
    rig, _ = rig
    u = data.draw(commands(mode))
    check_outcome(lambda: sh.simulate(rig, mode, u, options=sh.solver_options(method)))


@FUZZ
@given(dt=st.one_of(st.sampled_from(BAD + [5e-4, 1e-3, 2e-3]), st.floats(1e-5, 0.01)),
       x0=st.one_of(st.floats(-0.05, 0.05), st.sampled_from([math.nan, math.inf, 1e300, -200.0])),
       duration=st.one_of(st.none(), st.sampled_from([0.0, -1.0, math.nan, 0.05, 1e300])))
@counted(OUTCOMES)
def test_dt_x0_and_duration(dt, x0, duration):
    u = None if duration is not None else np.zeros(50)
    check_outcome(lambda: sh.simulate(sh.zhao2003(), "displacement", u, dt=dt, duration=duration, x0=x0))


INTS = [-(2**63), -1, 0, 1, 2, 5, 6, 50, 2**31, 2**64]
FLOATS = [0.0, -1e-6, 1e-14, 1e-9, 1e-6, 1e-3, 0.5, 1.0, 2.0, math.nan, math.inf, "1e-6", None]


@FUZZ
@given(method=st.sampled_from(["cvode", "rk4", "bogus"]), restart=st.sampled_from(["on_input_change", "never", "x"]),
       rtol=st.one_of(st.sampled_from(FLOATS[:-1]), st.floats(1e-12, 0.1)),
       rk4_substeps=st.sampled_from([-1, 0, 1, 3, 40, 2**31, 2**64]),
       max_steps=st.sampled_from(INTS), max_order=st.sampled_from(INTS),
       h_rho=st.sampled_from(FLOATS), v_ref=st.sampled_from(FLOATS))
@counted(OUTCOMES)
def test_solver_options(method, restart, rtol, rk4_substeps, max_steps, max_order, h_rho, v_ref):
    def run():
        o = sh.solver_options(method=method, rtol=rtol, restart=restart, rk4_substeps=rk4_substeps,
                              max_steps_per_sample=max_steps, max_order=max_order, rk4_h_rho=h_rho, rk4_v_ref=v_ref)
        return sh.simulate(sh.zhao2003(), "force", 1e4 * np.ones(N), options=o)

    check_outcome(run)


@FUZZ
@given(opening=st.lists(st.one_of(st.floats(-1, 2), st.sampled_from([math.nan, math.inf])), max_size=5),
       flow=st.lists(st.one_of(st.floats(-1, 2), st.sampled_from([math.nan, math.inf])), max_size=5),
       sort=st.booleans(), x=st.floats(-3, 3))
@counted(OUTCOMES)
def test_flow_curve_tables(opening, flow, sort, x):
    """Any table: the curve's methods give a finite value or a ValueError naming the field;
    never an out-of-bounds read (the sanitizer build runs these too)."""
    fc = _core.FlowCurve()
    fc.kind = _core.FlowCurve.Kind.Table
    fc.opening = sorted(opening) if sort else opening
    fc.flow = sorted(flow) if sort else flow
    for f in (fc.eval, fc.slope, fc.inverse):
        try:
            v = f(x)
        except ValueError as e:
            assert NAMED.search(str(e)) and "flow_curve" in str(e)
            continue
        assert math.isfinite(v)
    rig = sh.zhao2003()
    rig.flow_curve = fc
    check_outcome(lambda: sh.simulate(rig, "displacement", 0.005 * np.ones(20)))


@pytest.mark.parametrize("opening, flow", [([], []), ([0.0], [0.0]), ([0.0, 0.5, 1.0], [0.0, 0.5]),
                                           ([0.0, 1.0], [0.0, 0.5, 0.7])])
def test_flow_curve_short_tables_raise_instead_of_reading_out_of_bounds(opening, flow):
    fc = _core.FlowCurve()
    fc.kind = _core.FlowCurve.Kind.Table
    fc.opening, fc.flow = opening, flow
    for f in (fc.eval, fc.slope, fc.inverse):
        with pytest.raises(ValueError, match=r"invalid flow_curve\.(opening|flow) \(length\) = \d"):
            f(0.3)


ODD = st.sampled_from([None, 0, -1, 1.5, 2**70, math.nan, math.inf, "x", 5e-4, 0.1, 2])


@settings(max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(method=st.sampled_from(["eft", "rpsd"]), dt=ODD, alpha=ODD, lead_T=ODD, compute_delay=ODD,
       amplitude=st.sampled_from([0.0, 0.3, 30.0, 1e300]))
@counted(OUTCOMES)
def test_loop_keywords(method, dt, alpha, lead_T, compute_delay, amplitude):
    ag = amplitude * np.sin(np.linspace(0.0, 6.0, 100))
    kw = {"dt": dt, "alpha": alpha, "compute_delay": 0 if compute_delay is None else compute_delay}
    if method == "eft":
        check_outcome(lambda: sh.run_eft(sh.zhao2003(), ag, lead_T=lead_T, **kw))
    else:
        check_outcome(lambda: sh.run_rpsd(sh.zhao2003(), ag, amplitude_T=lead_T, **kw))
