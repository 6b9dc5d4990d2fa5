"""compare: NRMSE by hand, the FRF points, the files it writes."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import signal

import servohydraulics as sh
from servohydraulics import identification as lab

DT = 1e-3


def test_nrmse_equals_hand_computation_and_frf_ratio():
    """The 'measured' record is the preset with a 20 % stronger loop gain; compare runs
    the preset.  NRMSE = 100 rms(sim - meas) / std(meas) from an independent
    sh.simulate, and the FRF points' gain ratio equals |H_sim| / |H_meas| by hand."""
    rig = sh.zhao2003()
    t = np.arange(8001) * DT
    u = 2e-3 * signal.chirp(t, 0.2, t[-1], 5.0) * np.minimum(t / 0.5, 1)
    other = sh.zhao2003()
    other.G_p *= 1.2
    meas = sh.simulate(other, "displacement", command=u, dt=DT)
    rec = sh.Response({"time": t, "command": u, "displacement": meas.displacement, "force": meas.force})
    c = lab.compare(rec, rig, "displacement", frequencies=[1.0, 2.0, 4.0])
    sim = sh.simulate(rig, "displacement", command=u, dt=DT)
    for ch in ("displacement", "force"):
        m, s = rec.channels[ch], sim.channels[ch]
        hand = 100 * np.sqrt(np.mean((s - m) ** 2)) / np.std(m)
        assert c.nrmse(ch) == pytest.approx(hand, rel=1e-6)
        assert c.channels[ch]["nrmse_demeaned_pct"] == pytest.approx(100 * np.std(s - m) / np.std(m), rel=1e-6)
    pts = c.channels["displacement"]["frf"]
    hm = lab.h1(u, rec.displacement, DT).at([1.0, 2.0, 4.0])[0]
    hs = lab.h1(u, sim.displacement, DT).at([1.0, 2.0, 4.0])[0]
    np.testing.assert_allclose(pts["gain_ratio"], np.abs(hs) / np.abs(hm), rtol=1e-5)
    assert all(r < 1 for r in pts["gain_ratio"][1:])  # the weaker loop tracks less


def test_compare_command_writes_json_and_plots(tmp_path):
    rig = sh.zhao2003()
    t = np.arange(3001) * DT
    u = 1e-3 * np.sin(2 * np.pi * 2.0 * t)
    sim = sh.simulate(rig, "displacement", command=u, dt=DT)
    rec = tmp_path / "rec.csv"
    np.savetxt(rec, np.column_stack([t, u, sim.displacement + 1e-5, sim.force]), delimiter=",",
               header="time_s,command_m,displacement_m,force_N", comments="")
    rig_path = sh.save_rig(rig, tmp_path / "rig.toml")
    from servohydraulics.cli import main

    assert main(["compare", str(rec), "--rig", str(rig_path), "--mode", "displacement",
                 "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "comparison.json").read_text())
    d = data["channels"]["displacement"]
    meas = sim.displacement + 1e-5
    again = sh.simulate(rig, "displacement", command=u, dt=DT, x0=float(np.median(meas[:20])))  # the record's start
    assert d["nrmse_pct"] == pytest.approx(100 * np.sqrt(np.mean((again.displacement - meas) ** 2)) / np.std(meas),
                                           rel=1e-4)
    assert data["dt_s"] == pytest.approx(DT)
    assert (tmp_path / "out" / "overlay.png").stat().st_size > 0
    assert (tmp_path / "out" / "frf.png").stat().st_size > 0
    assert main(["compare", str(tmp_path / "missing.csv"), "--rig", str(rig_path), "--mode", "displacement",
                 "--out", str(tmp_path / "o2")]) == 2
