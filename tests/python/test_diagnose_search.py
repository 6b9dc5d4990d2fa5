"""The diagnosis' fits on RK4 (``engine.search_options``, ``engine.fit``): RK4 at the fewest
substeps whose run agrees with the search's error-controlled pair, chosen per fit start; a diverged
RK4 run retried at larger counts, then on the pair, whose stiff samples go to the core's
error-controlled Rosenbrock (with the pair's stiff samples by CVODE instead, ROS2 at fixed counts
before the pair, as in stop 45).  The oracles:
whole runs of the error-controlled pair (at the search's rtol and at the core's default), the
fixed-step run at the count the ladder lands on, and the same fit run on the pair alone."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.diagnosis import engine, workflow
from servohydraulics.diagnosis.effects import LIBRARY
from servohydraulics.diagnosis.effects import apply_area as _apply_area
from servohydraulics.identification.fit import rk4_options
from servohydraulics.identification.run import simulate_command
from servohydraulics.identification.segments import AGREEMENT, AGREEMENT_RMS
from servohydraulics.records import Record
from servohydraulics.simulate import METHODS, SimulationError

RIG = Path(__file__).resolve().parents[2] / "evaluation" / "utfsm_rig_0A.toml"
DT = 1e-3


def _rig() -> sh.Rig:
    """The UTFSM rig identified at 0 A (an MR damper specimen: its damping sets RK4's stability)."""
    return sh.load_rig(RIG)


def _record(rig: sh.Rig, c0: float | None = None) -> Record:
    """3 s of a 0.5-8 Hz chirp (8 mm) through ``rig`` (the damper's c0 [N s/m] raised to ``c0``:
    the hidden effect) by the core's default pair at rtol 1e-8, with 40 dB of noise."""
    truth = copy.copy(rig) if c0 is None else LIBRARY["mr_damper"].apply(
        rig, np.array([sh._core.mr_damper_law(rig)["alpha"], c0, sh._core.mr_damper_law(rig)["c1"]]))
    t = np.arange(int(3.0 / DT) + 1) * DT
    u = np.minimum(t / 0.3, 1.0) * 0.008 * np.sin(2 * np.pi * (0.5 + 2.5 * t) * t)
    r = simulate_command(truth, "displacement", u, DT, 0.0, None)
    rng = np.random.default_rng(11)
    ch = {"time": t, "command": u}
    for c in ("displacement", "force"):
        y = np.asarray(r.channels[c], float)
        ch[c] = y + rng.normal(0.0, 0.01 * float(np.sqrt(np.mean(y ** 2))), y.size)
    return Record(ch)


def _case(rec: Record) -> engine.Case:
    return engine.make_case(rec, "displacement", "chirp")


def _within(sim, ref, case) -> bool:
    worst, rms = engine.agreement(sim, ref, case)
    return worst <= AGREEMENT and rms <= AGREEMENT_RMS


def test_rk4_where_it_agrees_with_the_pair():
    rig = _rig()
    case = _case(_record(rig))
    opts = engine.search_options(rig, [case], 0.0, [case.x0_data])[0]
    assert opts.rk4_substeps in engine.SEARCH_RK4_SUBSTEPS and opts.rk4_flag_rtol == 0.0
    run = engine.simulate_case(rig, case, 0.0, case.x0_data, options=opts)
    # the oracles: the search's pair (rtol 1e-6) and the decisions' (the core's default rtol 1e-8)
    assert _within(run, engine.simulate_case(rig, case, 0.0, case.x0_data, search=True), case)
    assert _within(run, engine.simulate_case(rig, case, 0.0, case.x0_data), case)
    # the fewest: one count fewer does not agree (or is not tried: 3 is the first)
    i = engine.SEARCH_RK4_SUBSTEPS.index(opts.rk4_substeps)
    if i > 0:
        fewer = engine.simulate_case(rig, case, 0.0, case.x0_data,
                                     options=rk4_options(engine.SEARCH_RK4_SUBSTEPS[i - 1]))
        assert not _within(fewer, engine.simulate_case(rig, case, 0.0, case.x0_data, search=True), case)


def test_a_diverged_rk4_run_climbs_the_ladder():
    """A damper 400 times the identified one: RK4 at 3 substeps diverges within milliseconds; the
    run is RK4 at the ladder's first count that holds (bit for bit that run), near the pair's (a
    stable run, not a diverging one), and ``agrees`` (the fit's end check) says whether it is within
    ``AGREEMENT`` of it (where not, the fit goes on from there on the pair)."""
    rig = _rig()
    case = _case(_record(rig))
    law = sh._core.mr_damper_law(rig)
    stiff = LIBRARY["mr_damper"].apply(rig, np.array([law["alpha"], 1e6, law["c1"]]))
    with pytest.raises(SimulationError, match="diverged"):
        simulate_command(stiff, "displacement", case.u, case.dt, case.x0_data, rk4_options(3))
    run = engine.simulate_case(stiff, case, 0.0, case.x0_data, options=rk4_options(3))
    held = None
    for n in engine.SEARCH_RK4_LADDER:
        try:
            held = simulate_command(stiff, "displacement", case.u, case.dt, case.x0_data, rk4_options(n))
            break
        except SimulationError:
            continue
    assert held is not None
    for c in engine.SIM_CHANNELS:
        np.testing.assert_array_equal(run[c], held.channels[c])
    pair = engine.simulate_case(stiff, case, 0.0, case.x0_data, search=True)
    worst, rms = engine.agreement(run, pair, case)
    assert worst <= 10 * AGREEMENT and rms <= 10 * AGREEMENT_RMS
    assert engine.agrees(stiff, [case], 0.0, [case.x0_data], [rk4_options(3)]) == _within(run, pair, case)


def test_the_pair_where_no_count_agrees():
    """Coulomb friction's switch on an 8 mm chirp to 8 Hz: a fixed step straddles the reversals (the
    force differs by a fraction of its std at RK4's and ROS2's largest counts alike), so the fit keeps
    the pair."""
    rig = _rig()
    case = _case(_record(rig))
    coulomb = LIBRARY["coulomb_friction"].apply(rig, np.array([700.0]))
    ref = engine.simulate_case(coulomb, case, 0.0, case.x0_data, search=True)
    assert not _within(engine.simulate_case(coulomb, case, 0.0, case.x0_data,
                                            options=rk4_options(engine.SEARCH_RK4_SUBSTEPS[-1])), ref, case)
    assert not _within(engine.simulate_case(coulomb, case, 0.0, case.x0_data,
                                            options=engine.ros2_options(16)), ref, case)
    opts = engine.search_options(coulomb, [case], 0.0, [case.x0_data])[0]
    assert not engine.fixed_step(opts) and opts.rtol == engine.run_options(True).rtol


def _utfsm_10s_case():
    """The first 10 s of the UTFSM chirp at 1 A (benchmarks/lab_speed.py's diagnose10 record)."""
    from shared_data import shared_path

    from servohydraulics.records import read_record

    full = read_record(shared_path("real-data/utfsm-mts-mrdamper/chirp20Hz_1A.csv"))
    n = int(round(10.0 / full.dt)) + 1
    return _case(Record({k: np.asarray(v)[:n] for k, v in full.channels.items()}))


def test_the_pairs_stiff_samples_by_rodas4_agree_with_cvodes():
    """The diagnosis' pair, the search's (rtol 1e-6) and the decisions' (1e-8), does its stiff samples by the
    core's error-controlled RODAS4 (``SEARCH_STIFF_ROSENBROCK``, ``DECISION_STIFF_ROSENBROCK``,
    ``ROSENBROCK_ORDER``), not CVODE, and finds them by Hairer's stiffness test as well (``STIFFNESS_TEST``).
    On the diagnose10 record through the 0 A rig with 700 N of Coulomb friction (half its samples stiff) and
    with LuGre at its static limit (sigma_0 1e10 N/m: round 1's answer there), each run agrees with the same
    pair doing them by CVODE, an independent integrator, at its own tolerance, and with the CVODE pair at rtol
    1e-8: the search's to a tenth of the fits' test, the decisions' to a hundredth.  Where no sample is stiff
    (the 0 A rig) the two pairs are the same run to the bit.  Without fixed ROS2 rungs the ladder keeps the
    pair on the Coulomb rig."""
    case = _utfsm_10s_case()
    rig = _rig()
    rigs = {"coulomb": LIBRARY["coulomb_friction"].apply(rig, np.array([700.0])),
            "lugre at its bound": LIBRARY["lugre_friction"].apply(rig, np.array([1e10, 780.0])), "0 A": rig}
    for search in (True, False):
        o = engine.run_options(search)
        assert o.stiff_rosenbrock and o.rosenbrock_order == 4 and o.stiffness_test
    cvode_tight = engine.run_options(False)
    cvode_tight.stiff_rosenbrock = False
    for name, r in rigs.items():
        tight = simulate_command(r, "displacement", case.u, case.dt, case.x0_data, cvode_tight)
        for search, share in ((True, 0.1), (False, 0.01)):
            ros = simulate_command(r, "displacement", case.u, case.dt, case.x0_data, engine.run_options(search))
            o = engine.run_options(search)
            o.stiff_rosenbrock = False
            cv = simulate_command(r, "displacement", case.u, case.dt, case.x0_data, o)
            chans = [{c: s.channels[c] for c in engine.SIM_CHANNELS} for s in (ros, cv, tight)]
            if name == "0 A":
                assert ros.work.stiff_samples == 0
                for c in engine.SIM_CHANNELS:
                    np.testing.assert_array_equal(chans[0][c], chans[1][c])
                continue
            assert ros.work.stiff_samples > 1000 and abs(ros.work.stiff_samples - cv.work.stiff_samples) <= \
                0.01 * cv.work.stiff_samples, name
            for other in chans[1:]:
                worst, rms = engine.agreement(chans[0], other, case)
                assert worst <= share * AGREEMENT and rms <= share * AGREEMENT_RMS, (name, search, worst, rms)
    opts = engine.search_options(rigs["coulomb"], [case], 0.0, [case.x0_data])[0]
    assert not engine.fixed_step(opts)


def test_ros2_where_no_rk4_count_agrees(monkeypatch):
    """The first 10 s of the UTFSM chirp at 1 A (±2 mm) through the 0 A rig with 700 N of Coulomb
    friction (benchmarks/lab_speed.py's diagnose10 record; studies/diagnose_run_costs.py): no RK4 count
    agrees with the pair (the tanh law's slope F_c / (m v_stick) is outside RK4's stability region),
    ROS2 at the fewest of its counts that does is chosen, the count below it does not agree, and the
    chosen run stays within the fits' test of the pair's at the core's default tolerance too.  (The
    ladder of stop 45, the pair's stiff samples by CVODE: ``SEARCH_STIFF_ROSENBROCK`` False brings the ROS2
    rungs (8, 16) back.)"""
    monkeypatch.setattr(engine, "SEARCH_STIFF_ROSENBROCK", False)
    monkeypatch.setattr(engine, "SEARCH_ROS2_SUBSTEPS", (8, 16))
    case = _utfsm_10s_case()
    coulomb = LIBRARY["coulomb_friction"].apply(_rig(), np.array([700.0]))
    ref = engine.simulate_case(coulomb, case, 0.0, case.x0_data, search=True)
    for k in engine.SEARCH_RK4_SUBSTEPS:
        assert not _within(engine.simulate_case(coulomb, case, 0.0, case.x0_data, options=rk4_options(k)), ref, case)
    opts = engine.search_options(coulomb, [case], 0.0, [case.x0_data])[0]
    assert opts.method == METHODS["ros2"] and opts.ros2_substeps in engine.SEARCH_ROS2_SUBSTEPS
    run = engine.simulate_case(coulomb, case, 0.0, case.x0_data, options=opts)
    assert _within(run, ref, case)
    assert engine.agrees(coulomb, [case], 0.0, [case.x0_data], [opts])
    i = engine.SEARCH_ROS2_SUBSTEPS.index(opts.ros2_substeps)
    if i > 0:
        fewer = engine.ros2_options(engine.SEARCH_ROS2_SUBSTEPS[i - 1])
        assert not _within(engine.simulate_case(coulomb, case, 0.0, case.x0_data, options=fewer), ref, case)
    tight = engine.simulate_case(coulomb, case, 0.0, case.x0_data)  # the core's default, rtol 1e-8
    worst, rms = engine.agreement(run, tight, case)
    assert worst <= 2 * AGREEMENT and rms <= 2 * AGREEMENT_RMS


def test_the_fit_on_rk4_lands_where_the_fit_on_the_pair_does(monkeypatch):
    """The MR damper candidate fitted to a record with a damper 20 % stronger than the nominal one:
    the fit on RK4 and the same fit on the search's pair alone end within a tenth of a standard
    error of each other (the HAC intervals), both near the truth."""
    rig = _rig()
    c0_true = 1.2 * sh._core.mr_damper_law(rig)["c0"]
    rec = _record(rig, c0_true)
    setup = workflow._prepare([rec], rig, "displacement", ["mr_damper"], 1, False, False)
    x0 = tuple(c.x0_data for c in setup.cases)
    sims = engine.simulate_all(rig, setup.cases, 0.0, x0)
    ctx = workflow._context(setup, workflow._State(rig=rig, tau=0.0, x0=x0, sims=sims))
    space = engine.Space(LIBRARY["mr_damper"], ctx, ())
    start = space.absent.copy()
    lengths = engine.series_lengths(setup.cases)
    rig0, tau0 = space.rig_and_tau(start, 0.0)
    chosen = engine.search_options(rig0, setup.cases, tau0, x0)
    assert all(o.rk4_substeps > 0 for o in chosen)
    rk4 = engine.fit(space, setup.cases, start, 0.0, "all", x0)
    monkeypatch.setattr(engine, "search_options", lambda rig, cases, tau, x0s: [engine.run_options(True)] * len(cases))
    pair = engine.fit(space, setup.cases, start, 0.0, "all", x0)
    sd = np.sqrt(np.diag(engine.covariance(space, pair, lengths)))
    assert np.all(np.isfinite(sd))
    assert np.all(np.abs(rk4.z - pair.z) <= 0.1 * sd)
    c0 = space.to_external(rk4.z)[1]
    assert abs(c0 / c0_true - 1.0) < 0.05


@pytest.mark.parametrize("continuation, checks, expect", [
    ("pair", [False], ["rk4 3", "pair"]),  # the default: straight on to the pair
    ("search", [False, True], ["rk4 3", "rk4 8"]),  # chosen again, and it agrees at its result
    ("search", [False, False], ["rk4 3", "rk4 8", "pair"]),  # chosen again, disagrees again: the pair
    ("search", [True], ["rk4 3"]),  # the first result agrees: no continuation
])
def test_a_fit_whose_fixed_step_stopped_agreeing_goes_on_as_fit_continuation_says(monkeypatch, continuation, checks,
                                                                                  expect):
    """``engine.fit``'s continuation (``FIT_CONTINUATION``): the integrators its runs used, in order, where the
    end checks (``agrees``) answer ``checks`` and the integrator choice (``search_options``) gives RK4 at 3
    substeps at the start and at 8 where it is asked again; each fit ends on a result the last check accepted
    or on the pair, and the choice is asked again once at most."""
    rig = _rig()
    rec = _record(rig, 1.2 * sh._core.mr_damper_law(rig)["c0"])
    setup = workflow._prepare([rec], rig, "displacement", ["mr_damper"], 1, False, False)
    x0 = tuple(c.x0_data for c in setup.cases)
    ctx = workflow._context(setup, workflow._State(rig=rig, tau=0.0, x0=x0,
                                                   sims=engine.simulate_all(rig, setup.cases, 0.0, x0)))
    space = engine.Space(LIBRARY["mr_damper"], ctx, ())
    used, answers, choices = [], iter(checks), iter([[rk4_options(3)], [rk4_options(8)]])
    real = engine.simulate_all

    def simulate_all(rig, cases, tau, x0s, search=False, options=None):
        o = options[0]
        name = f"rk4 {o.rk4_substeps}" if engine.fixed_step(o) else "pair"
        if not used or used[-1] != name:
            used.append(name)
        return real(rig, cases, tau, x0s, search, options)

    monkeypatch.setattr(engine, "FIT_CONTINUATION", continuation)
    monkeypatch.setattr(engine, "simulate_all", simulate_all)
    monkeypatch.setattr(engine, "agrees", lambda *a: next(answers))
    monkeypatch.setattr(engine, "search_options", lambda *a: next(choices))
    res = engine.fit(space, setup.cases, space.absent.copy(), 0.0, "all", x0, max_nfev=4)
    assert used == expect
    assert next(answers, None) is None  # every check asked for was made
    assert np.all(np.isfinite(res.z)) and res.nfev >= len(expect)


def test_a_repeated_run_is_served_from_the_cache_and_equals_a_fresh_run():
    """``engine.RUNS``: a run made again (the same rig, command, delay, initial displacement and
    options) is the first run's arrays, read-only, and bit for bit what the core gives when asked
    again; a different rig, delay, start or integrator is a run of its own."""
    rig = _rig()
    case = _case(_record(rig))
    engine.RUNS.clear()
    h0, m0 = engine.RUNS.hits, engine.RUNS.misses
    a = engine.simulate_case(rig, case, 0.0, 0.0, search=True)
    b = engine.simulate_case(copy.copy(rig), case, 0.0, 0.0, search=True)  # an equal rig, another object
    assert (engine.RUNS.hits - h0, engine.RUNS.misses - m0) == (1, 1)
    assert b is a
    fresh = engine.run_case(rig, case, 0.0, 0.0, search=True)
    for c in engine.SIM_CHANNELS:
        assert np.array_equal(a[c], fresh[c])
        assert not a[c].flags.writeable
        with pytest.raises(ValueError):
            a[c][0] = 1.0
    other = copy.copy(rig)
    other.K_v *= 1.01
    runs = [engine.simulate_case(other, case, 0.0, 0.0, search=True),
            engine.simulate_case(rig, case, 1e-3, 0.0, search=True),
            engine.simulate_case(rig, case, 0.0, 1e-4, search=True),
            engine.simulate_case(rig, case, 0.0, 0.0, search=False),
            engine.simulate_case(rig, case, 0.0, 0.0, options=rk4_options(4))]
    assert engine.RUNS.hits - h0 == 1 and engine.RUNS.misses - m0 == 6
    for r in runs:
        assert not np.array_equal(r["force"], a["force"])
    engine.RUNS.clear()


def test_the_run_cache_keeps_its_byte_bound_and_diagnose_leaves_it_empty():
    rig = _rig()
    case = _case(_record(rig))
    one = sum(a.nbytes for a in engine.run_case(rig, case, 0.0, 0.0, search=True).values())
    small = engine.RunCache(max_bytes=2 * one)
    for x0 in (0.0, 1e-5, 2e-5):
        key = small.key(rig, case, 0.0, x0, engine.run_options(True))
        small.put(key, engine.run_case(rig, case, 0.0, x0, search=True))
    assert small._bytes <= 2 * one and len(small._runs) == 2
    assert small.get(small.key(rig, case, 0.0, 0.0, engine.run_options(True)))[0] is False  # the oldest went
    assert small.get(small.key(rig, case, 0.0, 2e-5, engine.run_options(True)))[0] is True
    sh.diagnose([_record(rig)], rig, candidates=["viscous_damping"], max_effects=1, progress=False)
    assert len(engine.RUNS._runs) == 0 and engine.RUNS._bytes == 0


def test_a_diagnosis_that_returns_leaves_the_runs_of_one_still_running():
    """Two diagnoses on two threads: the one that returns first must not empty the cache under the other (its
    runs would be made again: time, not results); the last one to return empties it."""
    import threading

    rig = _rig()
    case = _case(_record(rig))
    key = engine.RUNS.key(rig, case, 0.0, 0.0, engine.run_options(True))
    inside, leave = threading.Event(), threading.Event()

    def long_running():
        with engine.RUNS.session():
            engine.RUNS.put(key, engine.run_case(rig, case, 0.0, 0.0, search=True))
            inside.set()
            leave.wait(60)

    t = threading.Thread(target=long_running)
    t.start()
    try:
        assert inside.wait(60)
        sh.diagnose([_record(rig)], rig, candidates=["viscous_damping"], max_effects=1, progress=False)
        assert engine.RUNS.get(key)[0] is True  # the other's run is still served
    finally:
        leave.set()
        t.join(60)
    assert len(engine.RUNS._runs) == 0 and engine.RUNS._bytes == 0  # the last one out emptied it


def test_the_progress_bar_counts_the_look_alikes_it_fits(monkeypatch):
    """The bar's total grows by the shortlist's look-alikes (keep 1: viscous damping's two look-alikes are
    fitted too), so that its count never runs past its total."""
    import io

    from tqdm import tqdm

    bars = []

    def progress(total, enabled, desc):
        bars.append(tqdm(total=total, desc=desc, file=io.StringIO(), leave=True))
        return bars[-1]

    monkeypatch.setattr(workflow, "_progress", progress)
    rig = _rig()
    d = sh.diagnose([_record(rig)], rig, candidates=["viscous_damping", "coulomb_friction", "lugre_friction"],
                    keep=1, max_effects=1, progress=True)
    fitted = sum(1 for c in d.candidates if c.delta_bic is not None)
    assert fitted == 3  # the best screened and its two look-alikes
    bar = bars[0]
    assert bar.n == 3 + fitted <= bar.total == 3 + fitted


def test_the_run_cache_key_tells_every_field_of_the_rig_apart():
    """The cache (like identify's ``segments.Target``) keys a run by ``repr(rig)``: a rig that differs in any
    one field, effect switch or flow-curve point must have a key of its own (else a run of another rig is
    served).  The oracle: every property of ``sh.Rig`` changed alone."""
    base = _rig()
    case = _case(_record(base))
    key = engine.RUNS.key(base, case, 0.0, 0.0, engine.run_options(True))
    props = [k for k in dir(base) if not k.startswith("_") and not callable(getattr(base, k))]
    assert len(props) >= 60
    for name in props:
        r = copy.copy(base)
        v = getattr(r, name)
        if name == "effects":
            flags = [f for f in dir(v) if not f.startswith("_") and isinstance(getattr(v, f), bool)]
            assert len(flags) >= 13
            for flag in flags:
                e2 = copy.copy(v)
                setattr(e2, flag, not getattr(e2, flag))
                r2 = copy.copy(base)
                r2.effects = e2
                assert engine.RUNS.key(r2, case, 0.0, 0.0, engine.run_options(True)) != key, flag
            continue
        if name == "flow_curve":
            fc = copy.copy(v)
            fc.flow = [f * 1.01 for f in fc.flow]
            r.flow_curve = fc
        elif isinstance(v, bool):
            setattr(r, name, not v)
        elif isinstance(v, (int, float)):
            setattr(r, name, float(v) * (1 + 1e-12) if v != 0 else 1e-9)
        else:  # an enum (mr_input, mr_law): its other value
            others = [m for m in type(v).__members__.values() if m != v]
            setattr(r, name, others[0])
        assert engine.RUNS.key(r, case, 0.0, 0.0, engine.run_options(True)) != key, name


def test_the_pairs_stiff_switch_at_100_steps_keeps_its_runs_and_leaves_cvode_the_stiff_samples(monkeypatch):
    """``engine.STIFF_STEPS`` (the diagnosis' 100 against the core's 24, docs/benchmarks.md, stops 45-46):
    dopri5 hands a sample to its stiff integrator past that many steps.  On the 0 A rig re-sized x30 by the
    load term (the sweep's loop re-fit ends there) the samples that passed 24 steps were accuracy-limited,
    not stiff: at 100, dopri5 alone takes every sample and agrees with the pair at 24 (its stiff integrator
    on those samples: another method) well inside the fits' test, at both tolerances.  On Coulomb
    friction's rig the samples are stiff and still go to the stiff integrator."""
    rig = _rig()
    t = np.arange(int(3.0 / DT) + 1) * DT
    u = np.minimum(t / 0.3, 1.0) * 0.008 * np.sin(2 * np.pi * (0.5 + 2.5 * t) * t)
    resized = _apply_area(rig, 30.0 * rig.A)
    coulomb = LIBRARY["coulomb_friction"].apply(rig, np.array([700.0]))
    for r, stiff in ((resized, False), (coulomb, True)):
        for search, tol in ((True, 0.1 * AGREEMENT), (False, 0.01 * AGREEMENT)):
            monkeypatch.setattr(engine, "STIFF_STEPS", None)
            ref = simulate_command(r, "displacement", u, DT, 0.0, engine.run_options(search))
            assert engine.run_options(search).stiff_steps == 24
            monkeypatch.undo()
            assert engine.STIFF_STEPS == 100 and engine.run_options(search).stiff_steps == 100
            run = simulate_command(r, "displacement", u, DT, 0.0, engine.run_options(search))
            assert ref.work.stiff_samples > 0
            assert (run.work.stiff_samples > 0) == stiff
            for c in ("displacement", "force"):
                y0, y1 = np.asarray(ref.channels[c], float), np.asarray(run.channels[c], float)
                assert np.max(np.abs(y1 - y0)) <= tol * np.std(y0), (c, search, stiff)


def test_the_fits_stop_where_a_step_gains_a_hundredth_of_a_unit_of_the_decisions_statistic():
    """``engine.fit_ftol``: a fit's relative stopping tolerance is FIT_STEP_GAIN over the residual's AR(1)
    effective sample size summed over its series, at most FIT_FTOL_MAX.  Oracle: the closed form n (1 - rho) /
    (1 + rho) of AR(1) series made with a known rho (white noise: n), within the estimate's sampling error."""
    rng = np.random.default_rng(47)

    def ar1(n: int, rho: float) -> np.ndarray:
        e = rng.normal(size=n)
        x = np.empty(n)
        x[0] = e[0]
        for i in range(1, n):
            x[i] = rho * x[i - 1] + e[i]
        return x

    assert engine.FIT_STEP_GAIN == 0.01 and engine.FIT_FTOL_MAX == 1e-4
    white = [rng.normal(size=50_000), 3.0 * rng.normal(size=50_000)]  # the scale of a series does not matter
    got = engine.fit_ftol(np.concatenate(white), [50_000, 50_000])
    assert got == pytest.approx(0.01 / 100_000, rel=0.03)
    n, rho = 100_000, 0.5
    got = engine.fit_ftol(ar1(n, rho), [n])
    assert got == pytest.approx(0.01 / (n * (1 - rho) / (1 + rho)), rel=0.05)
    n, rho = 2_000, 0.98  # n_eff about 20: 0.01 / n_eff is above the cap
    assert engine.fit_ftol(ar1(n, rho), [n]) == 1e-4
