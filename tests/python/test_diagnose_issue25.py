"""Diagnose, issue 25: the fixes for the two blind misses and for the real record's manual step,
each on a small record of the independent simulator (evaluation/diagnose_eval/independent_plant.py,
no code shared with the core the workflow uses) where the workflow before the fix fails and the
workflow now passes, the hidden truth as the oracle.

* A piston mass that is a large share of a small rig's moving mass (the blind test's 60 kg on a
  150 kg structure, 6 cm^2 piston, 50 Hz valve) was beyond the candidate's range (0.3 m): its fit
  stopped at the bound and the valve took the rest.
* A mass the load cell sees (the blind miss: a 60 kg piston on the actuator's side of the load
  cell, F = p A = (m + 60 kg) a + ..., named compressibility plus valve dynamics) adds m a to the
  measured force: the moving_mass candidate, screened by the structure's balance residual against
  the acceleration.
* A wrong load-pressure term in the nominal model (the UTFSM rig identified at 0 A) made every
  force candidate cost displacement, so none passed: the force candidates now re-fit the model's
  load-pressure term with them over its whole range ("off" included).
* An actuator the model believes too small (the generic start's, sized from a record at low force)
  makes a force cost the displacement too much: the force candidates re-fit the actuator's size too.
"""

from __future__ import annotations

import dataclasses

from independent_records import gen, independent_record

import servohydraulics as sh
from servohydraulics.diagnosis import LIBRARY
from servohydraulics.diagnosis.effects import _a
from servohydraulics.records import Record


def _record(rig: str, duration: float, seed: int, snr: float, scale: float = 1.0, **truth) -> Record:
    """The evaluation's displacement command for ``rig`` (times ``scale``) through the independent
    simulator with ``truth`` hidden, white noise at ``snr`` dB on displacement and force."""
    return independent_record("displacement", rig, duration, seed, snr, scale, **truth)


def _names(d) -> list[str]:
    return [e["name"] for e in d.effects]


def _param(d, name: str, key: str) -> dict:
    return d.effects[_names(d).index(name)]["parameters"][key]


#: the look-alikes of a piston mass in displacement control (the library restricted to keep the test fast)
PISTON_LOOK_ALIKES = ["piston_mass", "compressibility", "servovalve_dynamics", "command_delay"]


def test_a_heavy_piston_on_a_small_rig_is_named_piston_mass(monkeypatch) -> None:
    """rigD (150 kg, 6 cm^2, 50 Hz valve; the model's piston 5 kg) with a 60 kg piston: the load
    cell sees its inertia (F = p A - m_p a).  Named piston_mass, m_p within 3 % of 60 kg with a
    95 % interval that covers it.  With the former range (up to 0.3 m = 45 kg) the same record is
    not: the fit stops at the bound and a look-alike wins."""
    rec = _record("rigD", 2.0, 11, 40.0, m_p=60.0)
    nominal = gen.nominal_rig("displacement", "rigD")
    d = sh.diagnose(rec, nominal, mode="displacement", progress=False, candidates=PISTON_LOOK_ALIKES, max_effects=1)
    assert _names(d) == ["piston_mass"], d.summary
    p = _param(d, "piston_mass", "m_p")
    assert abs(p["value"] - 60.0) < 0.03 * 60.0 and p["status"] == "identified"
    assert p["interval_95"][0] <= 60.0 <= p["interval_95"][1], p

    monkeypatch.setattr(LIBRARY["piston_mass"], "bounds", lambda ctx: (_a(0.0), _a(0.3 * ctx.rig.m)))
    old = sh.diagnose(rec, nominal, mode="displacement", progress=False, candidates=PISTON_LOOK_ALIKES,
                      max_effects=1)
    assert _names(old) != ["piston_mass"] or _param(old, "piston_mass", "m_p")["status"] == "at bound", old.summary


def test_a_mass_the_load_cell_sees_is_named_moving_mass() -> None:
    """rigD (150 kg structure, 6 cm^2, 50 Hz valve) with 60 kg more moving mass on the load cell's
    structure side (the independent simulator's structure mass 210 kg: the load cell measures its
    inertia, force residual 60 kg x acceleration).  Named moving_mass, m within 3 % of 210 kg with a
    95 % interval that covers it, ahead of the look-alikes that only lower the oil-column frequency
    (piston mass behind the load cell, a softer oil column, the valve)."""
    rec = _record("rigD", 2.0, 13, 40.0, m=210.0)
    nominal = gen.nominal_rig("displacement", "rigD")
    d = sh.diagnose(rec, nominal, mode="displacement", progress=False,
                    candidates=PISTON_LOOK_ALIKES + ["moving_mass"], max_effects=1)
    assert _names(d) == ["moving_mass"], d.summary
    p = _param(d, "moving_mass", "m")
    assert abs(p["value"] - 210.0) < 0.03 * 210.0 and p["status"] == "identified", p
    assert p["interval_95"][0] <= 210.0 <= p["interval_95"][1], p


def test_a_wrong_load_pressure_term_no_longer_blocks_the_force_candidate() -> None:
    """rigC (a light damper frame) with 800 N of Coulomb friction, its supply 21 MPa; the model
    believes the load-pressure term at a supply of 3 MPa (an identification at low load cannot
    see it), so that the friction's extra load pressure would cost the model a fifth of its flow.
    Now: coulomb_friction is named with F_c within 10 % of 800 N, the model's supply re-fitted with
    it (above 10 MPa or off), and the displacement gap does not grow.  (Before issue 25 the friction
    was not named on this record; with the load term's re-fit switched off, other changes of
    issue 25 now name it as well, so no counterfactual half is kept here.)"""
    rec = _record("rigC", 2.0, 5, 40.0, load_pressure=True, p_s=21e6, friction="coulomb", F_c=800.0)
    nominal = gen.nominal_rig("displacement", "rigC")
    nominal.effects.load_pressure, nominal.p_s = True, 3e6
    cands = ["coulomb_friction", "viscous_damping", "load_pressure"]
    d = sh.diagnose(rec, nominal, mode="displacement", progress=False, candidates=cands, max_effects=1)
    assert _names(d)[:1] == ["coulomb_friction"], d.summary
    assert abs(_param(d, "coulomb_friction", "F_c")["value"] - 800.0) < 0.1 * 800.0
    p_s = _param(d, "coulomb_friction", "p_s")["value"]
    assert p_s is None or p_s > 10e6, p_s  # None: infinite, the term switched off
    assert d.gap_after["displacement"] <= d.gap_before["displacement"]


def test_an_actuator_the_model_believes_too_small_is_re_sized_with_the_force_candidate() -> None:
    """rigC with 800 N of Coulomb friction; the model's actuator is eight times too small (A, K_v, K_a,
    C_l and F_cap divided by 8: the same no-load loop, eight times the cost of a force to the displacement,
    the way the generic start sizes an actuator from a record at low force).  The friction is named within
    10 % of 800 N, the actuator re-fitted with it (the load term A) to within 15 % of the truth, and the
    displacement gap does not grow."""
    from servohydraulics.diagnosis.effects import apply_area

    rec = _record("rigC", 2.0, 5, 40.0, friction="coulomb", F_c=800.0)
    truth = gen.nominal_rig("displacement", "rigC")
    nominal = apply_area(truth, truth.A / 8.0)
    d = sh.diagnose(rec, nominal, mode="displacement", progress=False,
                    candidates=["coulomb_friction", "viscous_damping", "load_pressure"], max_effects=1)
    assert _names(d)[:1] == ["coulomb_friction"], d.summary
    assert abs(_param(d, "coulomb_friction", "F_c")["value"] - 800.0) < 0.1 * 800.0
    assert abs(_param(d, "coulomb_friction", "A")["value"] - truth.A) < 0.15 * truth.A
    assert d.gap_after["displacement"] <= d.gap_before["displacement"]


def test_the_loop_is_re_fitted_once_the_actuator_is_re_sized() -> None:
    """The same record and too-small actuator, and the model's valve off as well (f_v 0.6 times, zeta_v 1.5
    times rigC's): once the friction's fit has re-sized the actuator, the loop re-fit (K_v, f_v, zeta_v with
    the friction) is kept, both channels' gaps fall below the greedy model's, and F_c moves to within 1 % of
    the hidden 800 N.  The loop's values are nuisance parameters: they are not checked against rigC's (here
    f_v 49 Hz, zeta_v 0.39 against 120 Hz, 0.8; the independent simulator's valve is not the core's)."""
    from servohydraulics.diagnosis.effects import apply_area

    rec = _record("rigC", 2.0, 5, 40.0, friction="coulomb", F_c=800.0)
    truth = gen.nominal_rig("displacement", "rigC")
    nominal = apply_area(truth, truth.A / 8.0)
    nominal.f_v, nominal.zeta_v = 0.6 * truth.f_v, 1.5 * truth.zeta_v
    d = sh.diagnose(rec, nominal, mode="displacement", progress=False,
                    candidates=["coulomb_friction", "viscous_damping", "load_pressure"], max_effects=1)
    assert _names(d) == ["coulomb_friction"], d.summary
    loop = [j for j in d.joint_refit if "loop" in j.effects]
    assert len(loop) == 1 and loop[0].kept, loop
    assert all(loop[0].gap_joint[c] < loop[0].gap_greedy[c] for c in ("displacement", "force")), loop[0]
    assert abs(_param(d, "coulomb_friction", "F_c")["value"] - 800.0) < 0.01 * 800.0
    assert d.gap_after["displacement"] < d.gap_before["displacement"]


def test_the_loop_alone_re_fitted_on_the_displacement_restores_the_tracking() -> None:
    """``joint.loop_refit_displacement`` (tried where the joint loop re-fit was refused): rigC with 800 N of
    Coulomb friction, the model right about the friction but its valve off (f_v 0.6 times, zeta_v 1.5 times
    rigC's).  The loop alone, fitted on the displacement channel with the friction held, is kept (BIC better
    by at least the workflow's DELTA_BIC_MIN); the
    displacement gap falls below the model's and to no more than the model with rigC's own valve values
    gives (the oracle: the fit can reach them), and the force gap is not worse."""
    import copy

    import numpy as np

    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import Context
    from servohydraulics.diagnosis.joint import loop_refit_displacement
    from servohydraulics.diagnosis.workflow import DELTA_BIC_MIN

    rec = _record("rigC", 2.0, 5, 40.0, friction="coulomb", F_c=800.0)
    truth = LIBRARY["coulomb_friction"].apply(gen.nominal_rig("displacement", "rigC"), np.array([800.0]))
    model = copy.copy(truth)
    model.f_v, model.zeta_v = 0.6 * truth.f_v, 1.5 * truth.zeta_v
    cases = [engine.make_case(rec, "displacement", "rec")]
    x0s = engine.refine_x0(model, cases, 0.0)
    sims = engine.simulate_all(model, cases, 0.0, x0s)
    # the loop candidate reads only the context's rig and mode; the peaks are placeholders
    ctx = Context(rig=model, nominal=model, mode="displacement", peak_spool=1.0, peak_pressure=1.0,
                  peak_x=float(np.max(np.abs(cases[0].meas["displacement"]))), rms_v=0.1, dt=rec.dt)
    info, new = loop_refit_displacement(model, model, 0.0, cases, x0s, sims, 1, 1, ctx, DELTA_BIC_MIN)
    assert info.kept and new is not None, info.reason
    oracle = engine.gap(engine.simulate_all(truth, cases, 0.0, engine.refine_x0(truth, cases, 0.0)), cases)
    g0, g1 = info.gap_greedy, info.gap_joint
    assert g1["displacement"] < g0["displacement"] and g1["force"] <= g0["force"], info
    print(f"displacement {100 * g0['displacement']:.3g} -> {100 * g1['displacement']:.3g} % (rigC's valve: "
          f"{100 * oracle['displacement']:.3g} %); force {100 * g0['force']:.2g} -> {100 * g1['force']:.2g} %")
    assert g1["displacement"] <= 1.02 * oracle["displacement"], (g1, oracle)


def test_a_significant_but_immaterial_third_correction_is_not_named() -> None:
    """The evaluation's r021 (generate.py's issue-25 plan, item 21, seed 2003, 4 s): the paper's rig with the
    load-pressure term at a 12 MPa supply and 250 N of Coulomb friction, forces to 95 kN, 55 dB.  The two
    hidden effects are named with their values (p_s and F_c within 5 %); a third candidate then passes the
    statistical tests at this noise level (moving_mass, a mass 0.07 % off: BIC better by 1,408) but closes
    under ``MATERIAL_MIN`` of the nominal model's gap above the noise floor (0.28 %), and is reported, not
    named.  Without the materiality test it was named third (the evaluation of stop 35).  Another candidate the
    BIC alone would take third (viscous damping, in numpy 2.4 / scipy 1.17's rounding) may be stopped by the
    held-out test instead: only what the statistics passed is left to materiality."""
    from servohydraulics.diagnosis.engine import MATERIAL_MIN
    from servohydraulics.diagnosis.workflow import DELTA_BIC_MIN

    plan = gen.plan_issue25()
    assert plan[21]["effects"] == [("load_pressure", 12e6), ("coulomb", 250.0)], plan[21]
    channels, _, _ = gen.make_record((21, plan[21], 2003, 4.0))
    nominal = gen.nominal_rig("displacement", "paper")
    d = sh.diagnose(Record(channels), nominal, mode="displacement", progress=False, max_effects=3,
                    candidates=["load_pressure", "coulomb_friction", "moving_mass", "viscous_damping"])
    assert _names(d) == ["load_pressure", "coulomb_friction"], d.summary
    assert abs(_param(d, "load_pressure", "p_s")["value"] - 12e6) < 0.05 * 12e6
    assert abs(_param(d, "coulomb_friction", "F_c")["value"] - 250.0) < 0.05 * 250.0
    third = {c.name: c for c in d.candidates if c.round == 3 and c.delta_bic is not None}
    mass = third["moving_mass"]  # passed every statistical test; only materiality stopped it
    assert mass.delta_bic >= DELTA_BIC_MIN and mass.rejection.startswith("closes "), mass
    assert mass.share_closed < MATERIAL_MIN, mass
    for c in third.values():  # any other candidate the BIC alone would take is stopped by a test too
        assert not c.accepted and c.rejection, c
        if c.rejection.startswith("closes "):
            assert c.share_closed < MATERIAL_MIN, c
    # the second effect, ten and more times the force noise, is well above the threshold
    second = next(c for c in d.candidates if c.name == "coulomb_friction" and c.accepted)
    assert second.share_closed > 3 * MATERIAL_MIN, second


def test_the_loop_alone_is_kept_where_it_gives_back_the_nominal_models_tracking() -> None:
    """``loop_refit_displacement``'s second rule: rigC with 800 N of Coulomb friction; the lab's nominal model
    is right about the friction with its valve 20 % slow (f_v 0.8 times rigC's); the model the effects left
    has lost the tracking (f_v 0.6 times, zeta_v 1.5 times).  With the BIC rule out of reach
    (``dbic_min`` infinite) the loop alone is kept because it brings every channel back to no worse than the
    nominal model's (it can reach rigC's own valve, which tracks better than the nominal's); without the
    nominal's gaps it is refused."""
    import copy

    import numpy as np

    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import Context
    from servohydraulics.diagnosis.joint import loop_refit_displacement

    rec = _record("rigC", 2.0, 5, 40.0, friction="coulomb", F_c=800.0)
    truth = LIBRARY["coulomb_friction"].apply(gen.nominal_rig("displacement", "rigC"), np.array([800.0]))
    nominal, model = copy.copy(truth), copy.copy(truth)
    nominal.f_v = 0.8 * truth.f_v
    model.f_v, model.zeta_v = 0.6 * truth.f_v, 1.5 * truth.zeta_v
    cases = [engine.make_case(rec, "displacement", "rec")]

    def gaps(rig):
        x0s = engine.refine_x0(rig, cases, 0.0)
        sims = engine.simulate_all(rig, cases, 0.0, x0s)
        return x0s, sims, engine.gap(sims, cases)

    _, _, g_nominal = gaps(nominal)
    x0s, sims, g_model = gaps(model)
    assert g_model["displacement"] > g_nominal["displacement"], (g_model, g_nominal)
    # the loop candidate reads only the context's rig and mode; the peaks are placeholders
    ctx = Context(rig=model, nominal=model, mode="displacement", peak_spool=1.0, peak_pressure=1.0,
                  peak_x=float(np.max(np.abs(cases[0].meas["displacement"]))), rms_v=0.1, dt=rec.dt)
    info, new = loop_refit_displacement(model, model, 0.0, cases, x0s, sims, 1, 1, ctx, np.inf, g_nominal)
    print(f"displacement / force gap [%]: nominal {100 * g_nominal['displacement']:.4g} / "
          f"{100 * g_nominal['force']:.3g}, "
          f"model {100 * g_model['displacement']:.4g} / {100 * g_model['force']:.3g}, loop alone "
          f"{100 * info.gap_joint['displacement']:.4g} / {100 * info.gap_joint['force']:.3g}")
    assert info.kept and new is not None and "no worse than the nominal" in info.reason, info.reason
    assert all(info.gap_joint[c] <= g_nominal[c] for c in g_nominal), (info.gap_joint, g_nominal)
    refused, none = loop_refit_displacement(model, model, 0.0, cases, x0s, sims, 1, 1, ctx, np.inf)
    assert not refused.kept and none is None, refused.reason


def test_a_piston_screened_below_the_shortlist_is_fitted_as_a_look_alike_and_named() -> None:
    """The evaluation's r004 (generate.py's issue-25 plan, item 4, seed 2003, 4 s): rigC (80 kg, 10 cm^2,
    120 Hz valve) with a 40 kg piston behind the load cell, 40 dB.  The linearised screening ranks the piston
    below the shortlist's three (a heavier piston and a softer oil column lower the oil-column frequency
    alike); compressibility, in the shortlist, brings it in as its look-alike, and its fit names it:
    piston_mass alone, m_p within 3 % of 40 kg with a 95 % interval that covers it.  When only the
    best-screened candidate brought its look-alikes, the piston was not fitted and compressibility was named
    with a delay term beside it (stop 35's evaluation)."""
    from servohydraulics.diagnosis.workflow import KEEP

    plan = gen.plan_issue25()
    assert plan[4]["effects"] == [("piston", 40.0)] and plan[4]["rig"] == "rigC", plan[4]
    channels, _, _ = gen.make_record((4, plan[4], 2003, 4.0))
    nominal = gen.nominal_rig("displacement", "rigC")
    d = sh.diagnose(Record(channels), nominal, mode="displacement", progress=False, max_effects=1,
                    candidates=["leakage", "load_pressure", "compressibility", "loop_delay", "piston_mass",
                                "moving_mass", "servovalve_dynamics"])
    ranked = sorted((c for c in d.candidates if c.round == 1 and c.screening_score is not None),
                    key=lambda c: -c.screening_score)
    names = [c.name for c in ranked]
    assert names.index("piston_mass") >= KEEP and names.index("compressibility") < KEEP, names
    assert _names(d) == ["piston_mass"], d.summary
    p = _param(d, "piston_mass", "m_p")
    assert abs(p["value"] - 40.0) < 0.03 * 40.0 and p["status"] == "identified", p
    assert p["interval_95"][0] <= 40.0 <= p["interval_95"][1], p


def _restore_setting():
    """rigC with 800 N of Coulomb friction (the independent simulator, 40 dB); the lab's nominal model has rigC's
    loop and no friction (displacement gap 3.8 %, force 94 %); the model the effects left has the friction right and
    its flow gain K_v 30 % low (7.6 %, 24 %): it tracks the displacement worse than the nominal model did."""
    import copy

    import numpy as np

    from servohydraulics.diagnosis import engine, workflow
    from servohydraulics.diagnosis.types import Accepted

    rec = _record("rigC", 2.0, 5, 40.0, friction="coulomb", F_c=800.0)
    nominal = gen.nominal_rig("displacement", "rigC")
    truth = LIBRARY["coulomb_friction"].apply(nominal, np.array([800.0]))
    model = copy.copy(truth)
    model.K_v = 0.7 * truth.K_v
    cases = [engine.make_case(rec, "displacement", "rec")]

    def run(rig):
        x0s = engine.refine_x0(rig, cases, 0.0)
        sims = engine.simulate_all(rig, cases, 0.0, x0s)
        return x0s, sims, engine.gap(sims, cases)

    setup = workflow._Setup(nominal, "displacement", cases, [], workflow.KEEP, True, True)
    x0s, sims, g_model = run(model)
    ctx = workflow._context(setup, workflow._State(rig=model, tau=0.0, x0=tuple(x0s), sims=sims))
    # the friction as the round accepted it, its re-fitted nominal terms none (the rig has no load terms on)
    space = engine.Space(LIBRARY["coulomb_friction"], ctx, ())
    z = space.to_internal(np.array([800.0]))
    accepted = [Accepted("coulomb_friction", space, z, z.copy(), z.copy(), None)]
    return nominal, truth, model, cases, run, x0s, sims, g_model, ctx, accepted


def test_the_restoring_re_fit_gives_back_the_tracking_the_model_lost() -> None:
    """``joint.restore_refit`` (issue 25 item 2: the diagnosis does not hand the lab a model that tracks a channel
    worse than its own).  In ``_restore_setting`` the model's displacement gap is above the nominal model's by
    more than ``RESTORE_MIN``; the re-fit of the friction with the loop, the force weighted down, is kept: every
    channel back to no worse than the nominal's, the displacement to no more than the truth's own model gives
    (the oracle: the fit can reach rigC's loop), the force keeps at least half of what the friction closed, and
    F_c stays within 5 % of the hidden 800 N.  Where no channel is worse than the nominal, it is not tried."""
    from servohydraulics.diagnosis.joint import RESTORE_GIVE_BACK, RESTORE_MIN, restore_refit

    nominal, truth, model, cases, run, x0s, sims, g_model, ctx, accepted = _restore_setting()
    _, _, g_nominal = run(nominal)
    _, _, g_truth = run(truth)
    assert g_model["displacement"] > (1 + RESTORE_MIN) * g_nominal["displacement"], (g_model, g_nominal)
    assert g_model["force"] < g_nominal["force"], (g_model, g_nominal)
    params = {"coulomb_friction": {"F_c": {"value": 800.0, "interval_95": None}}}
    info, new = restore_refit(accepted, params, model, g_nominal, 0.0, cases, x0s, sims, 1, ctx)
    g1 = info.gap_joint
    print(f"displacement / force gap [%]: nominal {100 * g_nominal['displacement']:.4g} / "
          f"{100 * g_nominal['force']:.3g}, model {100 * g_model['displacement']:.4g} / {100 * g_model['force']:.3g}, "
          f"truth {100 * g_truth['displacement']:.4g} / {100 * g_truth['force']:.3g}, restored "
          f"{100 * g1['displacement']:.4g} / {100 * g1['force']:.3g}; {info.reason}")
    assert info.kept and new is not None, info.reason
    assert all(g1[c] <= g_nominal[c] for c in g1), (g1, g_nominal)
    assert g1["displacement"] <= 1.02 * g_truth["displacement"], (g1, g_truth)
    assert g1["force"] <= g_model["force"] + RESTORE_GIVE_BACK * (g_nominal["force"] - g_model["force"])
    assert abs(new.parameters["coulomb_friction"]["F_c"]["value"] - 800.0) < 0.05 * 800.0, new.parameters
    assert new.rig.K_v != model.K_v and new.rig.F_c == new.parameters["coulomb_friction"]["F_c"]["value"]

    assert restore_refit(accepted, params, model, g_model, 0.0, cases, x0s, sims, 1, ctx) == (None, None)


def test_the_restoring_re_fit_weighs_the_other_channels_down_until_the_worse_one_is_back() -> None:
    """``joint._restored``, the rule that ends the restoring re-fit's weights: a fit is kept when every channel is
    back to no worse than the nominal's and each channel the effects improved keeps at least half of what they
    closed there (the nominal's 80 % force gap, the model's 10 %: up to 45 % kept, 46 % not); and the channels it
    is tried for."""
    from servohydraulics.diagnosis.joint import _restored, worse_than_nominal

    nominal, model = {"displacement": 0.02, "force": 0.8}, {"displacement": 0.025, "force": 0.1}
    assert _restored({"displacement": 0.02, "force": 0.44}, model, nominal) == (True, True)
    assert _restored({"displacement": 0.02, "force": 0.46}, model, nominal) == (True, False)
    assert _restored({"displacement": 0.021, "force": 0.2}, model, nominal) == (False, True)
    # tried for a channel more than RESTORE_MIN (2 %) above the nominal's, in displacement control only
    assert worse_than_nominal({"displacement": 0.0205, "force": 0.1}, nominal, "displacement") == ["displacement"]
    assert worse_than_nominal({"displacement": 0.0203, "force": 0.1}, nominal, "displacement") == []
    assert worse_than_nominal({"displacement": 0.0205, "force": 0.1}, nominal, "force") == []


def test_the_restoring_re_fit_keeps_an_actuator_that_carries_the_measured_force() -> None:
    """``joint._carry_peak_force``: the restoring re-fit weighs the force down, so the actuator's size (the load term
    A, its capacity F_cap scaled with it by ``apply_area``) is bounded where its capacity equals the records' peak
    force: the rig at that bound has F_cap = the peak force (the record check ``force_beyond_capacity`` then
    passes), and a rig whose capacity already falls short is not shrunk at all.  The space passed in is not
    changed."""
    import copy

    import numpy as np

    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.joint import _carry_peak_force

    _, _, model, _, _, _, _, _, ctx, _ = _restore_setting()
    for capacity in (1.5, 0.5):  # the rig's capacity, in peak forces (the space's own bound is half the size)
        rig = copy.copy(model)
        rig.F_cap = capacity * ctx.peak_force
        space = engine.Space(LIBRARY["coulomb_friction"], dataclasses.replace(ctx, rig=rig), (("A", "m^2"),))
        lo, hi = space.lo.copy(), space.hi.copy()
        narrowed = _carry_peak_force(space, rig, ctx.peak_force)
        assert np.array_equal(space.lo, lo) and np.array_equal(space.hi, hi)
        j = narrowed.n_main  # A, fitted as 1 / A: its smallest value is the reciprocal's upper bound
        assert narrowed.rec[j]
        at_bound, _ = narrowed.rig_and_tau(np.array([narrowed.absent[0], narrowed.hi[j]]), 0.0)
        if capacity > 1.0:
            assert abs(at_bound.F_cap - ctx.peak_force) < 1e-9 * ctx.peak_force, (at_bound.F_cap, ctx.peak_force)
            assert narrowed.hi[j] < hi[j]
        else:
            assert at_bound.A == rig.A and at_bound.F_cap == rig.F_cap
