"""The UTFSM records (../shared/real-data/utfsm-mts-mrdamper, never copied here):
the thesis' baselines as its README reports them, our H1 against the README's
table, a loop identified from the 0 A chirp predicting the 0 A sweep at least as
well as the thesis' G(s), and the rigs evaluation/utfsm_eval.py identified
(MR damper) against the thesis' models on every held-out record and channel."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest
from shared_data import shared_path

import servohydraulics as sh
from servohydraulics import identification as lab
from servohydraulics.identification import baselines as b
from servohydraulics.identification.fit import fit_options

FOLDER = "real-data/utfsm-mts-mrdamper"


def record(name):
    return sh.read_record(shared_path(f"{FOLDER}/{name}.csv"))


@pytest.mark.parametrize("name, lo, hi", [("chirp20Hz_0A", 4.45, 5.05), ("chirp20Hz_1A", 4.45, 5.05),
                                          ("sweep15Hz_0A", 2.65, 2.85), ("sweep15Hz_0p5A", 2.65, 2.85),
                                          ("sweep15Hz_1A", 2.65, 2.85)])
def test_thesis_linear_model_reproduces_readme(name, lo, hi):
    """README: G(s) leaves 4.5-5.0 % (chirps) and 2.7-2.8 % (sweeps) of the displacement
    std, 0.12-0.19 mm at worst; the figure is the error with its mean removed."""
    rec = record(name)
    x = b.thesis_displacement(rec.time, rec.command)
    assert lo <= lab.nrmse_demeaned_pct(x, rec.displacement) <= hi
    assert 0.115e-3 <= np.max(np.abs(x - rec.displacement)) <= 0.195e-3


def test_h1_reproduces_readme_frf_table():
    """README table (H1, Welch, 8192-point segments), chirp 0 A: gain and phase at 1-20 Hz."""
    rec = record("chirp20Hz_0A")
    f = np.array([1, 2, 5, 8, 10, 12, 15, 18, 20], dtype=float)
    gain = [0.988, 0.968, 0.825, 0.676, 0.595, 0.519, 0.432, 0.372, 0.338]
    phase = [-10.1, -18.9, -42.7, -61.7, -70.3, -78.3, -88.2, -96.5, -101.2]
    est = lab.h1(rec.command, rec.displacement, rec.dt)
    assert est.nperseg == 8192
    h, coh = est.at(f)
    np.testing.assert_allclose(np.abs(h), gain, atol=0.01)
    np.testing.assert_allclose(np.degrees(np.angle(h)), phase, atol=1.0)
    assert np.min(coh[1:]) >= 0.99


def test_thesis_bouc_wen_follows_the_measured_force_at_1A():
    """The thesis' MR model driven by the measured displacement of the 1 A sweep: the
    README's force range (-1.62 ... +1.70 kN) and a force in phase with the measurement."""
    rec = record("sweep15Hz_1A")
    F = b.thesis_mr_force(rec.displacement, rec.dt, 1.0)
    assert np.corrcoef(F, rec.force)[0, 1] > 0.95
    assert np.max(F) == pytest.approx(np.max(rec.force), rel=0.15)
    assert np.min(F) == pytest.approx(np.min(rec.force), rel=0.15)


def test_loop_identified_from_chirp_predicts_sweep_no_worse_than_thesis():
    """Identify the loop alone (generic start, displacement channel) from the 0 A chirp;
    predict the 0 A sweep from its command: displacement NRMSE <= the thesis' G(s) on the
    same record, with the issue's definition and with the error's mean removed."""
    chirp, sweep = record("chirp20Hz_0A"), record("sweep15Hz_0A")
    ident = sh.identify([chirp], mode="displacement", fit=["G_p", "f_v", "zeta_v"], channels=["displacement"],
                        progress=False)
    pred = lab.compare(sweep, ident.rig, "displacement", options=fit_options(ident.rig, [sweep], "displacement"))
    x = b.thesis_displacement(sweep.time, sweep.command)
    assert pred.nrmse("displacement") <= lab.nrmse_pct(x, sweep.displacement)
    assert pred.channels["displacement"]["nrmse_demeaned_pct"] <= lab.nrmse_demeaned_pct(x, sweep.displacement)
    assert ident.after[0].nrmse("displacement") <= lab.nrmse_pct(b.thesis_displacement(chirp.time, chirp.command),
                                                                 chirp.displacement)


#: (identified from, held out) at the same current; the rigs are those evaluation/utfsm_eval.py
#: identified (generic start, --specimen mr_damper) and committed in evaluation/utfsm_rigs/
HELD_OUT = (("chirp20Hz_0A", "sweep15Hz_0A"), ("sweep15Hz_0A", "chirp20Hz_0A"),
            ("chirp20Hz_1A", "sweep15Hz_1A"), ("sweep15Hz_1A", "chirp20Hz_1A"))
RIGS = Path(__file__).resolve().parents[2] / "evaluation" / "utfsm_rigs"
CURRENT = {"0A": 0.0, "1A": 1.0}
#: held-out cases where ours still loses (docs/lab-records.md says why); strict: a win fails
#: the test until this table is updated
KNOWN_LOSSES = {("chirp20Hz_0A", "sweep15Hz_0A", "force"):
                "the measured June 0 A |F/x| is 1.50-1.60 x the May one at 2-14 Hz (evaluation/utfsm_losses.py)",
                ("chirp20Hz_1A", "sweep15Hz_1A", "force"):
                "the measured June 1 A force lags the May one by 3-7.5 deg at 2-14 Hz (evaluation/utfsm_losses.py)"}


@functools.cache
def held_out(train: str, test: str) -> tuple[dict, dict]:
    """(ours, thesis) NRMSE [%] per channel on the held-out record."""
    rec = record(test)
    rig = sh.load_rig(RIGS / f"identified_from_{train}.toml")
    sim = lab.simulate_record(rig, rec, "displacement", options=fit_options(rig, [rec], "displacement"))
    ours = {ch: lab.nrmse_pct(sim.channels[ch], rec.channels[ch]) for ch in ("displacement", "force")}
    thesis = {"displacement": lab.nrmse_pct(b.thesis_displacement(rec.time, rec.command), rec.displacement),
              "force": lab.nrmse_pct(b.thesis_mr_force(rec.displacement, rec.dt, CURRENT[test.split("_")[1]]),
                                     rec.force)}
    return ours, thesis


@pytest.mark.parametrize("channel", ["displacement", "force"])
@pytest.mark.parametrize("train, test", HELD_OUT)
def test_held_out_no_worse_than_thesis(train, test, channel, request):
    """Ours (the committed rig identified from `train`, driven by the held-out record's
    command alone) <= the thesis' model (G(s) from the command for displacement; its
    Bouc-Wen driven by the MEASURED displacement for force) on the held-out record."""
    if (train, test, channel) in KNOWN_LOSSES:
        request.applymarker(pytest.mark.xfail(strict=True, reason=KNOWN_LOSSES[(train, test, channel)]))
    ours, thesis = held_out(train, test)
    assert ours[channel] <= thesis[channel], (ours, thesis)
