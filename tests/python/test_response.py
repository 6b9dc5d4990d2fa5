"""The one response type and the one error (sh.Response, sh.SimulationError), the
record file round trip of every channel, and the package's import hygiene."""

from __future__ import annotations

import importlib
import pickle
import sys

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.records import read_record, write_record
from servohydraulics.response import channel_units

N = 400  #: samples of the short runs [-]


def _ag(n: int = N, dt: float = 5e-4) -> np.ndarray:
    """0.15 g at 2 Hz, faded in [m/s^2]."""
    t = np.arange(n) * dt
    return 0.15 * 9.81 * np.sin(2 * np.pi * 2.0 * t) * np.minimum(t / 0.05, 1.0)


def _runs(rig: sh.Rig) -> dict[str, sh.Response]:
    t = np.arange(N) * 5e-4
    return {"plant": sh.simulate(rig, command=1e-3 * np.sin(2 * np.pi * 2 * t)),
            "eft": sh.run_eft(rig, ground_acceleration=_ag()),
            "rpsd": sh.run_rpsd(rig, ground_acceleration=_ag()),
            "tracking": sh.run_tracking(rig, 1e-3 * np.sin(2 * np.pi * 2 * t))}


# ---- one type, one shape --------------------------------------------------------------


def test_every_runner_returns_a_response(calibrated):
    """The same attributes on every kind; channels and units from one table."""
    for kind, res in _runs(calibrated).items():
        assert isinstance(res, sh.Response) and res.kind == kind
        assert res.success and res.status == "ok" and res.message == "ok"
        assert res.dt == 5e-4 and len(res) == N and res.work.rows == N
        assert res.time is res.channels["time"]
        assert res.displacement is res.channels["displacement"] is res.channels.displacement
        assert set(res.units) == set(res.channels)
        table = channel_units(kind, res.mode)
        assert all(res.units[n] == table[n] for n in res.channels)
        assert res.units["force"] == "N" and res.units["time"] == "s"
        assert res.warnings() == [] and isinstance(res.warnings(), list)
        df = res.to_pandas()
        assert list(df.columns) == list(res.channels) and df.attrs["units"] == res.units
        np.testing.assert_array_equal(df["force"].to_numpy(), res.force)


def test_command_unit_follows_the_mode(calibrated):
    assert sh.simulate(calibrated, mode="force", duration=0.01).units["command"] == "N"
    assert sh.simulate(calibrated, mode="displacement", duration=0.01).units["command"] == "m"
    assert sh.run_eft(calibrated, ground_acceleration=_ag(20)).units["command"] == "N"
    assert sh.run_rpsd(calibrated, ground_acceleration=_ag(20)).units["command"] == "m"


def test_channels_are_read_only(calibrated):
    res = sh.simulate(calibrated, duration=0.01)
    with pytest.raises(TypeError):
        res.channels["force"] = np.zeros(3)  # type: ignore[index]
    with pytest.raises(AttributeError, match="read-only"):
        res.channels.force = np.zeros(3)
    with pytest.raises(AttributeError, match="no attribute or channel 'forse'"):
        res.forse  # noqa: B018


def test_response_pickles(calibrated):
    """Sweeps ship responses across processes."""
    res = sh.run_rpsd(calibrated, ground_acceleration=_ag(50))
    back = pickle.loads(pickle.dumps(res))
    assert back.kind == "rpsd" and back.work.rows == 50 and back.rig.m == res.rig.m
    for name in res.channels:
        np.testing.assert_array_equal(back.channels[name], res.channels[name])


# ---- records keep every channel ----------------------------------------------------------


@pytest.mark.parametrize("kind", ["plant", "eft", "rpsd", "tracking"])
def test_record_round_trip_keeps_every_channel(calibrated, tmp_path, kind):
    """write_record(path, run) then read_record: every channel, the ground
    acceleration included, to the file's 10 significant digits; flags exactly."""
    res = _runs(calibrated)[kind]
    path = write_record(tmp_path / f"{kind}.csv", res)
    rec = read_record(path)
    assert rec.kind == "record" and rec.path == path
    assert set(rec.channels) == set(res.channels)
    for name, original in res.channels.items():
        scale = float(np.max(np.abs(original), initial=0.0))
        np.testing.assert_allclose(rec.channels[name], original, rtol=5e-10, atol=5e-10 * scale, err_msg=name)
    np.testing.assert_array_equal(rec.flags, res.flags)
    assert rec.units["ground_acceleration" if kind in ("eft", "rpsd") else "force"] in ("m/s^2", "N")
    assert res.to_csv(tmp_path / "again.csv").read_text() == path.read_text()


def test_old_ground_accel_column_reads_with_a_deprecation_warning(tmp_path):
    path = tmp_path / "old.csv"
    path.write_text("time,command,displacement,force,ground_accel\n0,0,0,0,1.5\n0.0005,0,0,0,2.5\n")
    with pytest.warns(DeprecationWarning, match="'ground_accel' is deprecated; name it 'ground_acceleration'"):
        rec = read_record(path)
    np.testing.assert_array_equal(rec.ground_acceleration, [1.5, 2.5])
    assert "ground_accel" not in rec.channels


# ---- one error ---------------------------------------------------------------------------


def _overrun() -> _core.SolverOptions:
    return sh.solver_options(max_steps_per_sample=1)


@pytest.mark.parametrize("run", ["simulate", "run_eft", "run_rpsd", "run_tracking"])
def test_failure_raises_simulation_error_with_the_partial_response(calibrated, run):
    """Every runner raises by default; the error carries the status and the rows
    up to the failure, the same rows raise_on_failure=False returns."""
    ag = _ag()
    call = {"simulate": lambda **kw: sh.simulate(calibrated, command=np.full(N, 1e-3), options=_overrun(), **kw),
            "run_eft": lambda **kw: sh.run_eft(calibrated, ground_acceleration=ag, solver_options=_overrun(), **kw),
            "run_rpsd": lambda **kw: sh.run_rpsd(calibrated, ground_acceleration=ag, solver_options=_overrun(), **kw),
            "run_tracking": lambda **kw: sh.run_tracking(calibrated, np.full(N, 1e-3), solver_options=_overrun(),
                                                         **kw)}[run]
    with pytest.raises(sh.SimulationError, match=r"failed at t = [0-9.e-]+ s: overrun") as info:
        call()
    err = info.value
    assert isinstance(err, RuntimeError) and err.status == "too_much_work"
    kept = call(raise_on_failure=False)
    assert not kept.success and kept.status == err.status and kept.message == str(err)
    assert len(err.partial) == len(kept) < N
    np.testing.assert_array_equal(err.partial.displacement, kept.displacement)
    assert kept.warnings()[-1] == kept.message
    assert kept.success is False and kept.work.rows == len(kept)


def test_old_names_are_deprecated_aliases():
    with pytest.warns(DeprecationWarning, match="TestMethodError is deprecated; use servohydraulics.SimulationError"):
        assert sh.TestMethodError is sh.SimulationError
    with pytest.warns(DeprecationWarning, match="SimulationResult is deprecated"):
        assert sh.SimulationResult is sh.Response
    sys.modules.pop("servohydraulics.methods", None)
    with pytest.warns(DeprecationWarning, match="methods is deprecated; import servohydraulics.loops"):
        methods = importlib.import_module("servohydraulics.methods")
    assert methods.run_eft is sh.run_eft and methods.TestMethodError is sh.SimulationError


# ---- defaults from the core --------------------------------------------------------------


def test_method_defaults_are_the_core_configs(calibrated):
    """Keywords left at None take EftConfig/RpsdConfig's defaults: the same run, sample for sample."""
    eft, rpsd = _core.EftConfig(), _core.RpsdConfig()
    a = sh.run_eft(calibrated, ground_acceleration=_ag(100))
    b = sh.run_eft(calibrated, ground_acceleration=_ag(100), dt=eft.dt, lead_T=eft.lead_T, alpha=eft.alpha)
    np.testing.assert_array_equal(a.force, b.force)
    a = sh.run_rpsd(calibrated, ground_acceleration=_ag(100))
    b = sh.run_rpsd(calibrated, ground_acceleration=_ag(100), dt=rpsd.dt, m_m=rpsd.model.m_m, c_m=rpsd.model.c_m,
                    amplitude_T=rpsd.amplitude_T, delay_T=rpsd.delay_T, alpha=rpsd.alpha)
    np.testing.assert_array_equal(a.calc_displacement, b.calc_displacement)
    assert a.rig.m == rpsd.model.m_m
