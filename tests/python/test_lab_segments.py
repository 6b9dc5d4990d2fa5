"""The time stage's segmented runs (identification/segments.py) against whole runs of the same
record (the oracle: the core's own run from the record's start), the warm-up against the decay of
the linearised loop, the fallback to whole runs, the run cache, and the block sweeps' stopping rule."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

import servohydraulics as sh
from servohydraulics.identification import records, segments
from servohydraulics.identification.coordinates import Coordinates
from servohydraulics.identification.fit import StageResult, fit_options
from servohydraulics.identification.run import simulate_record

DT = 1e-3


def mr_rig() -> sh.Rig:
    """The UTFSM frame with its MR damper as identified at 0 A (the diagnosis evaluation's rig)."""
    return sh.load_rig(Path(__file__).resolve().parents[2] / "evaluation" / "utfsm_rig_0A.toml")


def record(rig: sh.Rig, duration: float = 8.0, seed: int = 1) -> sh.Response:
    t = np.arange(int(round(duration / DT)) + 1) * DT
    u = 2e-3 * signal.chirp(t, 0.3, t[-1], 12.0) * np.minimum(t / 0.5, 1.0)
    sim = sh.simulate(rig, "displacement", command=u, dt=DT, options=sh.solver_options(rtol=1e-9))
    rng = np.random.default_rng(seed)
    return sh.Response({"time": t, "command": u, "displacement": sim.displacement + 2e-6 * rng.standard_normal(t.size),
                        "force": sim.force + 2.0 * rng.standard_normal(t.size)})


def test_segmented_runs_equal_the_whole_run_within_the_integrators_tolerance():
    """Two segments, each from rest at the measured displacement a warm-up before it, give the
    whole run's channels (the whole run from the record's start is the oracle) to within the
    pair's tolerance at rtol 1e-6: < 1e-4 of each channel's standard deviation at worst."""
    rig = mr_rig()
    rec = record(rig)
    options = fit_options(rig, [rec], "displacement")
    with segments.Target.build([rec], "displacement", ("displacement", "force"), options, None, rig, 2) as target:
        assert len(target.segments[0]) == 2 and target.segments[0][1].start > 0
        assert target.segments[0][1].keep - target.segments[0][1].start == int(np.ceil(
            segments.warmup_seconds(rig, "displacement", 0.0) / DT))
        whole = simulate_record(rig, rec, "displacement", options=options)
        worst, rms = target.gap(rig, [whole])
        assert worst < 1e-4 and rms < 1e-5 and target.agrees(rig, [whole])
        # the residual's layout is the whole record's: record-major, channel by channel
        e = target.residual(rig)
        ref = np.concatenate([(whole.channels[c] - rec.channels[c]) / np.std(rec.channels[c])
                              for c in ("displacement", "force")])
        assert e.shape == ref.shape and np.max(np.abs(e - ref)) < 1e-4


def test_warmup_is_fifteen_time_constants_of_the_slowest_mode():
    """The warm-up is 15 / (the slowest decay rate of the linearised loop), at least 0.5 s; a run
    started from rest mid-record has forgotten its start by then: started at a third of the record
    it agrees with the whole run after the warm-up (1e-4 of the std) and not before it."""
    rig = mr_rig()
    from servohydraulics.analysis import linearize

    lam = np.linalg.eigvals(np.asarray(linearize(rig, "displacement", x0=0.0).A, dtype=float))
    lam = lam[np.abs(lam) > 1e-9 * np.max(np.abs(lam))]
    w = segments.warmup_seconds(rig, "displacement", 0.0)
    assert w == pytest.approx(max(0.5, 15.0 / np.min(-lam.real)), rel=1e-12)
    rec = record(rig)
    n = rec.time.size
    a = n // 3
    warm = int(np.ceil(w / DT))
    target = segments.Target([rec], "displacement", ("displacement",), fit_options(rig, [rec], "displacement"),
                             None, [[segments.Segment(a - warm, a - warm, n)]])
    whole = simulate_record(rig, rec, "displacement", options=target.options)
    d = np.abs(target.simulations([rig])[0][0]["displacement"] - whole.displacement[a - warm:])
    sd = np.std(rec.displacement)
    assert np.max(d[warm:]) < 1e-4 * sd
    assert np.max(d[: warm // 10]) > 1e-3 * sd  # the start's transient, gone by the warm-up's end


def test_short_records_and_slow_controllers_run_whole():
    rig = mr_rig()
    rec = record(rig, duration=2.0)
    assert segments.split(rec, 0.5, 2) == segments.whole(rec)  # 1 s segments < 4 warm-ups
    long = record(rig, duration=8.0)
    assert len(segments.split(long, 0.5, 2)) == 2
    assert segments.split(long, 0.5, 2, dt=2 * DT) == segments.whole(long)  # a controller slower than the record
    assert segments.split(long, None, 2) == segments.whole(long)


def test_runs_are_cached_by_rig():
    rig = mr_rig()
    rec = record(rig, duration=4.0)
    t = segments.Target([rec], "displacement", ("displacement", "force"), fit_options(rig, [rec], "displacement"),
                        None, [segments.whole(rec)])
    a = t.residual(rig)
    b = t.residual(rig, {"displacement": 2.0, "force": 1.0})
    assert t.runs == 1
    n = rec.time.size
    np.testing.assert_array_equal(b[:n], 2 * a[:n])
    other = copy.copy(rig)
    other.G_p *= 1.01
    t.residuals([other, rig, None])
    assert t.runs == 2


def test_identify_falls_back_to_whole_runs_when_segments_disagree(monkeypatch):
    """The time stage runs RK4 in segments when that agrees with the pair's whole run of the start;
    with a warm-up far too short (monkeypatched) no segmented run agrees: identify fits on the pair's
    whole runs, and finds the same keys."""
    rig = mr_rig()
    rec = record(rig)
    fit = ["G_p", "f_v", "zeta_v"]
    ident = sh.identify([rec], rig=rig, fit=fit, channels=["displacement"], progress=False)
    assert ident.runs["segments"] == [2] and ident.runs["integrator"].startswith("rk4")
    monkeypatch.setattr(segments, "MIN_WARMUP", 1e-3)
    monkeypatch.setattr(segments, "WARMUP_DECAYS", 1e-3)
    fallback = sh.identify([rec], rig=rig, fit=fit, channels=["displacement"], progress=False)
    assert fallback.runs["segments"] == [1] and fallback.runs["integrator"].startswith("dopri5")
    for k in fit:  # the same fit either way (well within its uncertainty)
        assert abs(fallback.values[k] - ident.values[k]) < 0.1 * ident.std[k]


def test_a_block_fit_moved_only_beyond_its_resolution():
    """The block sweeps' stopping rule: a move counts when it exceeds both SWEEP_TOL and SWEEP_SD
    of the key's standard error; a key the records do not determine (a null Jacobian column) may
    move freely."""
    rng = np.random.default_rng(3)
    J = np.column_stack([rng.standard_normal(400), np.zeros(400)])
    r = rng.standard_normal(400)
    sd = float(np.sqrt(records.covariance(J[:, :1], r, None, [400]).matrix[0, 0]))
    active = np.array([True, True])
    z0 = np.zeros(2)

    def moved(dz):
        return records._moved(StageResult(z0 + dz, 0.0, 1, r, J), z0, active, [400])

    assert records.SWEEP_SD * sd > records.SWEEP_TOL
    assert not moved(np.array([0.5 * records.SWEEP_SD * sd, 50.0]))
    assert moved(np.array([2 * records.SWEEP_SD * sd, 0.0]))
    assert not moved(np.array([0.9 * records.SWEEP_TOL, 0.0]))  # below SWEEP_TOL never counts


def test_coordinates_apply_keeps_the_segments_rig_independent():
    """Segments of one rig never share state: two rigs evaluated together give their own runs."""
    rig = mr_rig()
    rec = record(rig, duration=8.0)
    coords = Coordinates.about(rig, ("G_p",))
    with segments.Target.build([rec], "displacement", ("displacement",), fit_options(rig, [rec], "displacement"),
                               None, rig, 2) as t:
        rigs = [coords.apply(rig, np.array([z])) for z in (0.0, 0.1)]
        together = t.residuals(rigs)
    for rig_i, e in zip(rigs, together):
        alone = segments.Target([rec], "displacement", ("displacement",), t.options, None, t.segments, 1)
        np.testing.assert_array_equal(alone.residual(rig_i), e)


def test_a_result_the_pairs_runs_would_move_is_polished_on_them(monkeypatch):
    """The end check: the pair's whole runs of the result move it by ``shift_sd`` standard errors
    (a thousandth here: RK4's bias is far below the fit's resolution); with the tolerance at 0 the
    result is polished on the pair's whole runs and ends where the RK4 fit did."""
    rig = mr_rig()
    rec = record(rig)
    fit = ["G_p", "f_v", "zeta_v"]
    start = copy.copy(rig)
    start.G_p, start.f_v = 1.2 * rig.G_p, 0.8 * rig.f_v
    ident = sh.identify([rec], rig=start, fit=fit, channels=["displacement"], progress=False)
    assert 0.0 <= ident.runs["shift_sd"] < 0.01 and not ident.runs["polished_on_whole_runs"]
    monkeypatch.setattr(records, "SHIFT_SD", 0.0)
    polished = sh.identify([rec], rig=start, fit=fit, channels=["displacement"], progress=False)
    assert polished.runs["polished_on_whole_runs"]
    for k in fit:
        assert abs(polished.values[k] - ident.values[k]) < 0.1 * ident.std[k]
        lo, hi = ident.intervals[k]
        assert lo <= getattr(rig, k) <= hi  # the truth inside the 95 % interval


def test_removal_runs_refuse_a_stiffer_rig_and_an_invalid_one():
    """``records._removal_runs``: a removal runs on the fit's RK4 segments only when RK4's automatic
    substep count for its rig (the core's rule from the plant's rate bound) is at most the fitted rig's;
    the fitted point itself comes back as the target's own residual, to the bit; a stiffer rig (the
    damper's Bouc-Wen gamma, which bounds this rig's rates, four times higher: more substeps) and a rig the
    core refuses (gamma infinite) come back None (the
    pair's whole runs decide), and a Target on the pair gives no fast runs at all."""
    from servohydraulics.identification.fit import automatic_substeps, rk4_options

    rig = mr_rig()
    rec = record(rig, duration=6.0)
    coords = Coordinates.about(rig, ("mr_gamma",))
    z_fit = np.zeros(1)
    n_fit = automatic_substeps(rig, [rec], "displacement")
    assert coords.kind == ("log",)
    stiff, soft, invalid = np.array([np.log(4.0)]), np.array([np.log(0.25)]), np.array([800.0])
    assert automatic_substeps(coords.apply(rig, invalid), [rec], "displacement") is None  # the core refuses gamma inf
    assert automatic_substeps(coords.apply(rig, stiff), [rec], "displacement") > n_fit  # the premise
    assert automatic_substeps(coords.apply(rig, soft), [rec], "displacement") <= n_fit
    with segments.Target.build([rec], "displacement", ("displacement", "force"), rk4_options(n_fit), None, rig,
                               2) as target:
        fast = records._removal_runs(target, rig, coords, z_fit, [rec], "displacement", None)
        points = [z_fit, stiff, soft, invalid]
        out = fast(points)
        np.testing.assert_array_equal(out[0], target.residual(rig))
        assert out[1] is None
        np.testing.assert_array_equal(out[2], target.residual(coords.apply(rig, soft)))
        assert out[3] is None
    pair = segments.Target([rec], "displacement", ("displacement",), fit_options(rig, [rec], "displacement"), None,
                           [segments.whole(rec)])
    assert records._removal_runs(pair, rig, coords, z_fit, [rec], "displacement", None) is None
