"""Bring your own controller: a Python class (a TrackingController subclass or any
object with reset() and command(...)) in the C++ RTHS loop, the built-ins as objects of
the same interface, the CLI's module:Class, and the criteria by name.

The oracle is the built-in C++ controller: a Python class that only delegates to it must
give the same signals and J, bit for bit (the arithmetic is the same C++ code; only the
call path differs)."""

from __future__ import annotations

import json
import math
import os
import textwrap
from pathlib import Path

import numpy as np
import pytest
from shared_data import shared_path
from test_rths import PUBLISHED_CASE1

from servohydraulics import rths
from servohydraulics.cli import main

R = rths.core
SIGNALS = ("command", "measured", "numerical", "actuator_force")


class Delegating:
    """Duck-typed: delegates every call to a built-in controller."""

    def __init__(self, name: str = "sample"):
        self.inner = rths.make_controller(name)
        self.resets = 0

    def reset(self):
        self.resets += 1
        self.inner.reset()

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
        return self.inner.command(desired, desired_velocity, desired_acceleration, measured, measured_force)


class DelegatingSubclass(rths.TrackingController):
    """A TrackingController subclass (the pybind11 trampoline) delegating to the built-in."""

    def __init__(self, name: str = "sample"):
        super().__init__()
        self.inner = rths.make_controller(name)

    def reset(self):
        self.inner.reset()

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
        return self.inner.command(desired, desired_velocity, desired_acceleration, measured, measured_force)


class Failing:
    """Raises at sample ``at`` (0-based), or returns ``value`` there."""

    def __init__(self, at: int, error: BaseException | None = None, value=None):
        self.at, self.error, self.value, self.k = at, error, value, 0

    def reset(self):
        self.k = 0

    def command(self, *args):
        k, self.k = self.k, self.k + 1
        if k == self.at:
            if self.error is not None:
                raise self.error
            return self.value
        return 0.0


@pytest.fixture(scope="module")
def short():
    return rths.embedded_case(1), rths.synthetic_record(duration=3.0)


def _trial(case, rec, controller, **kw):
    return rths.run_trial(case, rec, controller, seed=3, keep_signals=True, **kw)


@pytest.mark.parametrize("name", sorted(rths.CONTROLLERS))
def test_delegating_python_controllers_reproduce_each_builtin(short, name):
    """Duck-typed and subclassed, the delegating controller gives the built-in's run bit for bit."""
    case, rec = short
    ref = _trial(case, rec, name)
    assert ref.ok
    duck = Delegating(name)
    for ctrl in (duck, DelegatingSubclass(name), rths.make_controller(name)):
        t = _trial(case, rec, ctrl)
        assert t.ok and t.J == ref.J, type(ctrl).__name__
        for s in SIGNALS:
            np.testing.assert_array_equal(t.signals[s], ref.signals[s], err_msg=f"{type(ctrl).__name__} {s}")
    assert duck.resets == 2  # the loop resets it at construction and before the run


def test_builtins_are_objects_of_the_interface():
    """make_controller returns a TrackingController for every name; command takes the
    documented five floats (or a TrackingInput) and reset() restarts it."""
    args = (1e-3, 2e-2, 0.3, 4e-4, 50.0)
    for name in rths.CONTROLLERS:
        a, b = rths.make_controller(name), rths.make_controller(name)
        assert isinstance(a, rths.TrackingController)
        seq = [a.command(*args) for _ in range(5)]
        assert seq == [b.command(R.TrackingInput(*args)) for _ in range(5)]
        a.reset()
        assert [a.command(*args) for _ in range(5)] == seq
        assert all(math.isfinite(u) for u in seq) and seq[0] != 0.0
    # designed on another plant: the model-based feedforward follows the plant's coefficients
    stiff = rths.nominal_plant()
    stiff.k_e *= 2.0
    u = [rths.make_controller("model", plant=p).command(*args) for p in (rths.nominal_plant(), stiff)]
    assert u[0] != u[1]


def test_delegating_class_reproduces_the_published_case1_row():
    """The issue's acceptance: a class that only delegates to the built-in sample
    controller gives the built-in's J on the official data (same to round-off: here
    identical), and so the published row."""
    data = shared_path("rths-data/mat")
    case, rec = rths.load_case(data, 1), rths.load_record(data, "elcentro")
    ref = rths.case_reference(case, rec)
    builtin = rths.run_trial(case, rec, "sample", reference=ref).J
    mine = rths.run_trial(case, rec, Delegating(), reference=ref)
    np.testing.assert_allclose(mine.J, builtin, rtol=0, atol=1e-12)
    assert mine.J[0] == pytest.approx(PUBLISHED_CASE1[0], abs=0.1)
    for i in range(1, 9):
        assert mine.J[i] == pytest.approx(PUBLISHED_CASE1[i], abs=0.5), rths.J_NAMES[i]
    assert mine.criteria["J1_delay_ms"] == mine.J[0] == pytest.approx(4.6, abs=1e-9)


def test_an_exception_in_command_stops_the_run_and_is_reraised_with_sample_and_time(short):
    case, rec = short
    with pytest.raises(RuntimeError, match=r"Failing\.command\(\) raised at sample 100 \(t = 0\.0244140625 s\): "
                                           r"ZeroDivisionError: no") as info:
        rths.run_trial(case, rec, Failing(100, ZeroDivisionError("no")))
    e = info.value
    assert e.sample == 100 and e.time == 100 * rths.DT and isinstance(e.__cause__, ZeroDivisionError)
    # the subclass path: the same, and the loop stopped there (the run did not go on)
    class Sub(rths.TrackingController):
        def __init__(self):
            super().__init__()
            self.calls = 0

        def reset(self):
            self.calls = 0

        def command(self, *args):
            self.calls += 1
            if self.calls == 8:
                raise ValueError("bad gain")
            return 0.0
    sub = Sub()
    with pytest.raises(RuntimeError, match=r"Sub\.command\(\) raised at sample 7 .*ValueError: bad gain"):
        rths.run_trial(case, rec, sub)
    assert sub.calls == 8  # not called again after the failure
    # a command that is not a number: a TypeError naming what came back
    with pytest.raises(RuntimeError, match=r"sample 5 .*TypeError: command\(\) returned None: expected a float"):
        rths.run_trial(case, rec, Failing(5, value=None))
    # a NaN command is no exception: the loop stops and the trial says so
    t = rths.run_trial(case, rec, Failing(5, value=math.nan))
    assert not t.ok and t.failure_time == 5 * rths.DT and all(math.isnan(j) for j in t.J)


def test_an_exception_in_reset_and_an_interrupt(short):
    case, rec = short

    class BadReset(Delegating):
        def reset(self):
            raise OSError("rig offline")
    with pytest.raises(RuntimeError, match=r"BadReset\.reset\(\) raised at sample 0 \(t = 0\.0 s\): OSError"):
        rths.run_trial(case, rec, BadReset())
    with pytest.raises(KeyboardInterrupt):  # not wrapped: Ctrl-C stays Ctrl-C
        rths.run_trial(case, rec, Failing(3, KeyboardInterrupt()))
    # after a failure the same object runs again (reset clears it)
    f = Failing(10**9)
    assert rths.run_trial(case, rec, f).ok


def test_not_a_controller_is_refused_naming_the_value(short):
    case, rec = short

    class NoCommand:
        def reset(self):
            pass
    for bad, missing in ((object(), "reset(), command()"), (NoCommand(), "command()")):
        with pytest.raises(TypeError, match=rf"invalid controller = .*: not a tracking controller, it lacks "
                                            rf"{missing.replace('(', '[(]').replace(')', '[)]')}"):
            rths.run_trial(case, rec, bad)
    with pytest.raises(ValueError, match="invalid controller = 'pid'"):
        rths.make_controller("pid")


def test_run_case_with_an_object_runs_the_perturbed_trials_in_process(short):
    """An object cannot go to worker processes: run_case runs its perturbed trials one after
    another here, and gets the same table as the built-in's name (worker processes)."""
    case, rec = short
    a = rths.run_case(case, rec, Delegating(), perturbed=2, seed=5, progress=False)
    b = rths.run_case(case, rec, "sample", perturbed=2, seed=5, max_workers=2, progress=False)
    assert a["nominal"]["J"] == b["nominal"]["J"] and a["perturbed"]["J_mean"] == b["perturbed"]["J_mean"]
    assert list(a["nominal"]["criteria"]) == list(rths.J_NAMES)
    assert a["perturbed"]["criteria_mean"]["J2_rms_tracking_error_pct"] == a["perturbed"]["J_mean"][1]
    cols = list(a["table"].columns)
    assert all(n in cols for n in rths.J_NAMES) and "J1" not in cols
    assert set(a["table"]["controller"]) == {f"{__name__}:Delegating"}
    np.testing.assert_array_equal(a["table"][list(rths.J_NAMES)].to_numpy(), b["table"][list(rths.J_NAMES)].to_numpy())
    df = a["trial"].to_pandas()
    assert list(df.columns[:9]) == list(rths.J_NAMES) and df["J1_delay_ms"].iloc[0] == a["nominal"]["J"][0]


def _module(tmp_path, body: str, name: str = "my_ctrl"):
    (tmp_path / f"{name}.py").write_text(textwrap.dedent(body))
    return name


def test_cli_controller_module_class(tmp_path, monkeypatch, capsys):
    """--controller module:Class: the module from PYTHONPATH, the class built with no
    arguments, as the example's docstring says (PYTHONPATH=examples, 07_user_controller:
    Delegating); delegating to the built-in sample controller it writes the built-in's J,
    in the nominal trial and in the perturbed trials of the worker processes."""
    examples = Path(__file__).resolve().parents[2] / "examples"
    monkeypatch.syspath_prepend(str(examples))
    monkeypatch.setenv("PYTHONPATH", f"{examples}:{os.environ.get('PYTHONPATH', '')}")  # for the workers
    mod = "07_user_controller"
    outs = {}
    for spec in ("sample", f"{mod}:Delegating"):
        out = tmp_path / spec.replace(":", "_")
        assert main(["rths-benchmark", "--cases", "1", "--controller", spec, "--perturbed", "2", "--workers", "2",
                     "--quiet", "--out", str(out)]) == 0
        outs[spec] = json.loads((out / "results.json").read_text())
    mine = outs[f"{mod}:Delegating"]
    assert mine["meta"]["controller"] == f"{mod}:Delegating"
    assert mine["meta"]["controller_description"].startswith("Delegates to a built-in controller")
    assert mine["cases"]["1"]["nominal"]["J"] == outs["sample"]["cases"]["1"]["nominal"]["J"]
    assert mine["cases"]["1"]["nominal"]["criteria"] == outs["sample"]["cases"]["1"]["nominal"]["criteria"]
    # the perturbed trials: each worker process imported the module and built its own
    assert mine["cases"]["1"]["perturbed"] == outs["sample"]["cases"]["1"]["perturbed"]
    assert mine["meta"]["perturbed_stable"] == {"1": 2}


def test_run_benchmark_with_an_object_runs_in_process():
    """run_benchmark with a controller object (a TrackingController subclass: not
    picklable) and perturbed trials: no process pool, the built-in's figures."""
    from servohydraulics.rths.report import run_benchmark

    a = run_benchmark(None, cases="1", controller=DelegatingSubclass(), perturbed=2, progress=False)["results"]
    b = run_benchmark(None, cases="1", controller="sample", perturbed=2, workers=2, progress=False)["results"]
    assert a["cases"] == b["cases"] and a["meta"]["controller"] == f"{__name__}:DelegatingSubclass"


def test_cli_controller_errors_exit_2_naming_the_value(tmp_path, monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(tmp_path))
    _module(tmp_path, '''
        class NotOne:
            def reset(self):
                pass
        class Broken:
            def __init__(self):
                raise RuntimeError("no rig file")
            def reset(self):
                pass
            def command(self, *a):
                return 0.0
        thing = 3
    ''', "my_ctrl_bad")
    _module(tmp_path, "import not_installed_xyz\n", "my_ctrl_dep")
    cases = {"no_such_module_xyz:C": "module 'no_such_module_xyz' not found on PYTHONPATH",
             "my_ctrl_bad:Missing": "module 'my_ctrl_bad' (",
             "my_ctrl_bad:NotOne": "not a tracking controller, it lacks command()",
             "my_ctrl_bad:Broken": "Broken() raised RuntimeError: no rig file",
             "my_ctrl_bad:thing": "my_ctrl_bad.thing is a int, not a class",
             "pid": "expected one of ['ats', 'model', 'polynomial', 'sample'] or 'module:Class'",
             "my_ctrl_bad:": "expected a built-in name",
             "my_ctrl_dep:C": "importing module 'my_ctrl_dep' failed: ModuleNotFoundError: No module named "
                              "'not_installed_xyz'",
             "no_such_pkg_xyz.sub:C": "module 'no_such_pkg_xyz.sub' not found on PYTHONPATH"}
    for spec, text in cases.items():
        assert main(["rths-benchmark", "--cases", "1", "--controller", spec, "--quiet",
                     "--out", str(tmp_path / "o")]) == 2, spec
        err = capsys.readouterr().err
        assert f"invalid controller = {spec!r}" in err and text in err, (spec, err)
    assert "has no class 'Missing'" in (main(["rths-benchmark", "--cases", "1", "--controller", "my_ctrl_bad:Missing",
                                              "--quiet", "--out", str(tmp_path / "o")]) == 2
                                        and capsys.readouterr().err)
    assert not (tmp_path / "o").exists()  # refused before any run or file


def test_subclass_command_is_found_as_python_finds_it_and_the_object_is_freed(short):
    """The trampoline caches the class's command at reset(): an instance attribute that
    replaces it still wins (as in Python), and the controller is freed after the run (no
    reference cycle through the cache)."""
    import gc
    import weakref

    case, rec = short
    ref = _trial(case, rec, "sample")
    sub = DelegatingSubclass()
    inner = sub.inner
    sub.command = lambda *args: 0.0  # an instance attribute: no command from the class
    t = _trial(case, rec, sub)
    assert t.J != ref.J and np.all(t.signals["command"] == 0.0)
    del sub.command
    assert _trial(case, rec, sub).J == ref.J
    probe = weakref.ref(sub)
    del sub
    gc.collect()
    assert probe() is None and inner is not None


def test_calls_from_python_raise_at_once():
    """Called from Python (not by a loop), a Python controller's error is raised at once,
    and a TrackingController without overrides says what it lacks."""
    wrapped = rths.PythonController(Failing(1, ValueError("second call")))
    assert wrapped.command(1e-3) == 0.0
    with pytest.raises(RuntimeError, match=r"^Failing\.command\(\) raised at sample 1: ValueError: second call$"):
        wrapped.command(1e-3)
    with pytest.raises(RuntimeError, match=r"TrackingController\.reset\(\) raised at sample 0: TypeError: a "
                                           r"TrackingController subclass must define reset\(\)"):
        rths.TrackingController().reset()
