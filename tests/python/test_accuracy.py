"""Randomized accuracy (issues 16 and 26): the default method and the real-time
option against a tight-tolerance reference (ARKODE's explicit pair at rtol 1e-10,
confirmed by CVODE at the same tolerances) on hundreds of random valid rigs, in
displacement and in force control.  Every run is within the method's stated
tolerance (1e-3 of the peak displacement and force for the default, 1e-2 for
RK4) or says it is not (a non-ok status, or its accuracy check over its bound:
``work.error_estimate`` > 1): never silently off.  And the flags mean something:
they do not fire on runs well within the tolerance.  The rigs, the commands and
the counting are those of evaluation/accuracy_random_rigs.py (published in
docs/benchmarks.md); here 200 rigs of 0.4 s keep the test near a minute.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import servohydraulics as sh

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "evaluation"))
import accuracy_random_rigs as ar  # noqa: E402

RIGS = 200


@pytest.fixture(scope="module")
def survey() -> dict:
    return ar.survey(sh, RIGS, seed=2016, duration=0.4, progress=False)


def test_the_random_rigs_cover_both_modes_and_run():
    rng = np.random.default_rng(2016)
    modes = [ar.random_case(sh, rng, 0.4, 5e-4)[1] for _ in range(RIGS)]
    assert 0.35 * RIGS < modes.count("force") < 0.65 * RIGS


@pytest.mark.parametrize("which", ["default", "rk4"])
def test_never_silently_off(survey, which):
    c = survey["counts"][which]
    assert survey["reference_failed"] < 0.1 * RIGS
    assert c["silent"] == 0, f"{which}: silent wrong answers {c['silent_cases']}"
    assert c["within"] + c["flagged"] == RIGS - survey["reference_failed"]


def _runs(survey, which: str) -> list[tuple[float, bool]]:
    """(error, flagged) of each run of the survey by `which`."""
    col = list(survey["methods"]).index(which) + 2
    return [(row[col][0], row[col][1]) for row in survey["cases"]["rows"] if row[col][0] is not None]


def test_the_flags_do_not_fire_on_clearly_accurate_runs(survey):
    """Issue 26: RK4's former estimate fired on 58 % of accurate runs.  Its companion at twice the
    substeps measures the run's own error: no run within a fifth of RK4's 1e-2 is flagged, and of
    the runs within 1e-2 at most a tenth.  The default's check (of runs that turned stiff) flags no
    run within a fifth of its 1e-3."""
    rk4 = _runs(survey, "rk4")
    assert not [e for e, f in rk4 if f and e <= 0.2 * ar.TOLERANCE["rk4"]]
    within = [f for e, f in rk4 if e <= ar.TOLERANCE["rk4"]]
    assert sum(within) <= 0.1 * len(within), f"{sum(within)} of {len(within)} accurate RK4 runs flagged"
    assert sum(f for e, f in rk4 if e > ar.TOLERANCE["rk4"]) > 0  # the survey has misses to catch
    assert not [e for e, f in _runs(survey, "default") if f and e <= 0.2 * ar.TOLERANCE["default"]]


@pytest.mark.slow
@pytest.mark.parametrize("family", ["wide", "high_gain"])
def test_never_silently_off_on_the_wide_and_high_gain_families(family):
    """Issue 26, defect 4: the families where the default missed silently (masses, areas, gains and
    compressibility over decades; loop gains to 500 with stiff oil), drawn at a seed of their own:
    no silent miss of either method, and the default's flag fires on no run within a fifth of its
    tolerance.  RK4's may, rarely: it flags a sample whose load-cell force would jump (a velocity
    reversal at a near-Coulomb friction) within the band of states its error spans, also when the
    run happened to land on the right side (wide rig 0 at this seed: 2.5e-4 off, flagged); at most
    one in twenty of the runs."""
    res = ar.survey(sh, 40, seed=2026, duration=0.4, progress=False, family=family,
                    methods=("default", "rk4") if family == "wide" else ("default",))
    for which in res["methods"]:
        c = res["counts"][which]
        assert c["silent"] == 0, f"{family}, {which}: silent wrong answers {c['silent_cases']}"
        clear = [e for e, f in _runs(res, which) if f and e <= 0.2 * ar.TOLERANCE[which]]
        assert len(clear) <= (0.05 * len(_runs(res, which)) if which == "rk4" else 0), clear


def test_the_default_is_accurate_not_merely_flagged(survey):
    """Flagging everything would pass the test above: the default must be within its tolerance
    on nearly every rig, and RK4 on most."""
    n = RIGS - survey["reference_failed"]
    assert survey["counts"]["default"]["within"] >= 0.97 * n
    assert survey["counts"]["rk4"]["within"] >= 0.7 * n


def test_an_off_run_is_counted_silent():
    """The oracle can fail: an answer from a looser method with the flags ignored counts as silent."""
    rig = sh.zhao2003()
    rig.K_s, rig.C_F_force = 1.0, 0.5e-3  # the raised-gain force loop
    u = 5e4 * np.sin(2 * np.pi * 2.0 * np.arange(2000) * 5e-4)
    u[1200:] += 3e4
    ref = sh.simulate(rig, "force", u, options=sh.solver_options(method="cvode", rtol=1e-10,
                                                                  max_steps_per_sample=100000))
    two = sh.simulate(rig, "force", u, options=sh.solver_options(method="rk4", rk4_substeps=2))
    assert ar._error(two, ref) > ar.TOLERANCE["rk4"]
    assert two.work.inaccurate_samples > 0 and two.work.error_estimate > 1  # and the run flags it
    assert any(code == "run_accuracy" and "twice the RK4 substeps" in w for code, w in two.notes())


# Two rigs of evaluation/accuracy_random_rigs.py's high-gain family (stiff oil, strong valve, no
# servovalve dynamics): nearly every sample is stiff for the explicit pair and CVODE takes it.
HIGH_GAIN = {  # the loop amplifies the integration error about a million times: 20 % off, flagged
    "m": 43.7234, "k": 186749.0, "k_2": 110263.0, "c": 4174.69, "F_c": 0.0, "A": 0.0202267, "K_a": 1.52386e-14,
    "C_l": 5.57695e-11, "p_s": 13844800.0, "K_v": 0.294474, "K_s": 1.06603, "f_v": 166.112, "zeta_v": 0.721389,
    "G_p": 5.7417, "C_F_disp": 51.3314}
HIGH_GAIN_CALM = {  # as stiff, but the loop damps the error: the default is within 1e-3
    "m": 72.7327, "k": 205894.0, "k_2": 148600.0, "c": 915.038, "F_c": 0.0, "A": 0.00924061, "K_a": 1.36924e-13,
    "C_l": 8.8169e-11, "p_s": 19268200.0, "K_v": 0.0125616, "K_s": 0.924741, "f_v": 25.3585, "zeta_v": 0.564861,
    "G_p": 83.5975, "C_F_disp": 173.376}


def _high_gain_case(values: dict, amp: float, freq: float, step: float, duration: float = 0.5, dt: float = 5e-4):
    rig = sh.zhao2003()
    for k, v in values.items():
        setattr(rig, k, v)
    rig.effects.servovalve_dynamics = False
    t = np.arange(int(round(duration / dt)) + 1) * dt
    u = amp * np.sin(2 * np.pi * freq * t)
    u[t >= 0.6 * duration] += step
    return rig, u


def _run(rig, u, **kw):
    return sh.simulate(rig, "displacement", u, options=sh.solver_options(**kw))


def test_stiff_samples_that_miss_the_stated_accuracy_are_flagged():
    """Issue 26, defect 4: against ARKODE's explicit pair at rtol 1e-10 (no CVODE, no Newton), a
    stiff high-gain rig's run is within 1e-3 of the peak displacement and force or flags samples
    inaccurate; a looser rtol that misses by far is flagged, with a warning that says why."""
    rig, u = _high_gain_case(HIGH_GAIN, 0.00262353, 1.50547, -0.0148819)
    ref = sh.simulate(rig, "displacement", u, options=sh.solver_options(
        "arkode_erk", rtol=1e-10, atol_fraction=1e-3, max_steps_per_sample=1000000))
    default = _run(rig, u)
    assert default.work.stiff_samples > 0.9 * u.size
    assert ar._error(default, ref) <= ar.TOLERANCE["default"] or default.work.error_estimate > 1
    loose = _run(rig, u, rtol=1e-7)
    assert ar._error(loose, ref) > 10 * ar.TOLERANCE["default"]
    assert loose.work.inaccurate_samples > 0 and loose.work.error_estimate > 1
    assert any(code == "run_accuracy" and "turned stiff and its check" in w for code, w in loose.notes())
    assert not any(code == "run_accuracy" for code, _ in default.notes()) or default.work.error_estimate > 1


def test_the_check_off_leaves_the_result_and_drops_the_flag():
    """``stiff_check=False`` (the fits' search runs): the same run to the bit (the check's shadow
    only flags), without its flags and for less work (the shadow's steps and right-hand sides)."""
    rig, u = _high_gain_case(HIGH_GAIN, 0.00262353, 1.50547, -0.0148819)
    checked, unchecked = _run(rig, u, rtol=1e-7), _run(rig, u, rtol=1e-7, stiff_check=False)
    assert checked.work.inaccurate_samples > 0 and checked.work.error_estimate > 1
    for ch in ("displacement", "force", "pressure", "spool", "velocity"):
        np.testing.assert_array_equal(unchecked.channels[ch], checked.channels[ch])
    assert unchecked.work.inaccurate_samples == 0 and unchecked.work.error_estimate == 0
    assert unchecked.work.stiff_samples == checked.work.stiff_samples
    assert not any(code == "run_accuracy" for code, _ in unchecked.notes())


def test_stiff_samples_within_the_stated_accuracy_are_not_flagged():
    """The flag means something: on an equally stiff rig whose loop does not amplify the error,
    the default is within 1e-3 of the reference and flags nothing."""
    rig, u = _high_gain_case(HIGH_GAIN_CALM, 0.062815, 0.799468, 0.0238396)
    ref = sh.simulate(rig, "displacement", u, options=sh.solver_options(
        "arkode_erk", rtol=1e-10, atol_fraction=1e-3, max_steps_per_sample=1000000))
    default = _run(rig, u)
    assert default.work.stiff_samples > 0.5 * u.size
    assert ar._error(default, ref) <= ar.TOLERANCE["default"]
    assert default.work.inaccurate_samples == 0 and default.work.error_estimate <= 1


def test_the_cli_warns_when_the_default_misses(tmp_path, capsys):
    """Issue 26, defect 4 from the command line: `servohydraulics simulate` on the high-gain rig
    (its loop amplifies the stiff samples' integration error) writes a record the explicit
    reference at rtol 1e-10 puts more than 1e-3 off, and says so on stderr; the same rig under a
    small command, within 1e-3, gets no such warning."""
    from servohydraulics.cli import main
    from servohydraulics.excitations import sine

    rig, _ = _high_gain_case(HIGH_GAIN, 0.0, 1.0, 0.0)
    rig_file = sh.save_rig(rig, tmp_path / "high_gain.toml")
    ref_opts = sh.solver_options("arkode_erk", rtol=1e-10, atol_fraction=1e-3, max_steps_per_sample=1000000)
    for amp, misses in ((0.005, True), (0.00127, False)):
        out = tmp_path / f"r{amp}.csv"
        assert main(["simulate", "--rig", str(rig_file), "--amplitude", str(amp), "--frequency", "1",
                     "--duration", "0.25", "--out", str(out)]) == 0
        err = capsys.readouterr().err
        ref = sh.simulate(rig, "displacement", sine(amp, 1.0, 0.25, 5e-4), options=ref_opts)
        rec = sh.read_record(out)
        gap = max(np.max(np.abs(rec.displacement - ref.displacement)) / np.max(np.abs(ref.displacement)),
                  np.max(np.abs(rec.force - ref.force)) / np.max(np.abs(ref.force)))
        assert bool(gap > ar.TOLERANCE["default"]) is misses, gap
        assert ("warning: the run turned stiff and its check" in err) is misses, err


def _family_case(family: str, seed: int, index: int, duration: float = 1.0, dt: float = 5e-4):
    """Case `index` of evaluation/accuracy_random_rigs.py's draw of `family` at `seed`."""
    rng = np.random.default_rng(seed)
    for _ in range(index + 1):
        rig, mode, u = ar.family_case(sh, rng, duration, dt, family)
    return rig, mode, u


def _reference(rig, mode, u):
    return sh.simulate(rig, mode, u, options=ar._options(sh, "reference"))


def test_a_run_that_turned_stiff_is_checked_from_its_start():
    """Issue 26, defect 4, the last silent miss of the default (random family, seed 17, rig 41: a
    force loop that rings at the end of the record): the error of the explicit samples before the
    first stiff one is amplified later, in the result and in the shadow that starts there alike
    (the shadow's gap read 0.39 of its bound).  The whole-record check, a second run at rtol / 10
    from the start, sees it: the run is 1.03e-3 off the explicit reference at rtol 1e-10 and says
    so; with that check off only the shadow's verdict is left, under its bound."""
    rig, mode, u = _family_case("random", 17, 41)
    ref = _reference(rig, mode, u)
    run = sh.simulate(rig, mode, u)
    assert run.work.stiff_samples > 0
    assert ar._error(run, ref) > ar.TOLERANCE["default"]
    assert run.work.error_estimate > 1
    assert any(code == "run_accuracy" for code, _ in run.notes())
    # the same run with the checks off: bit-identical, and nothing says it misses
    unchecked = sh.simulate(rig, mode, u, options=sh.solver_options(stiff_check=False))
    assert np.array_equal(unchecked.force, run.force) and unchecked.work.error_estimate == 0


def test_rk4_flags_a_force_that_jumps_at_a_friction_reversal():
    """Issue 26, defect 4, the last silent miss of RK4 (high-gain family, seed 17, rig 61: 1.4 kg
    moving, 914 N of near-Coulomb friction, force loop gain 315): at the sample where the velocity
    reverses, RK4 and its companion at twice the substeps both land on the wrong side of zero, so
    the load-cell force is 2 F_c off (10 % of the peak) in both and their gap is small.  The check
    also measures how much a checked value bends over the band of states the run's error spans:
    the friction's sign flips inside it, and the run is flagged."""
    rig, mode, u = _family_case("high_gain", 17, 61)
    ref = _reference(rig, mode, u)
    rk4 = sh.simulate(rig, mode, u, options=sh.solver_options(method="rk4"))
    assert ar._error(rk4, ref) > ar.TOLERANCE["rk4"]
    assert rk4.work.error_estimate > 1 and rk4.work.inaccurate_samples > 0
