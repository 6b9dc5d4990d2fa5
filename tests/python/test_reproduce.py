"""The reproduction table: a fast subset of ``reproduce`` checked against the paper's numbers
(servohydraulics.paper; ``sh.reproduce`` is its driver)."""

from __future__ import annotations

import importlib
import json
import math

import pytest

rp = importlib.import_module("servohydraulics.paper.reproduce")

#: the paper's values of rows in the fast subset (None: a statement without a number)
PAPER = {"natural_frequency": 1.58, "T_ld_estimate": 13.0, "friction_free": 95.7, "friction_attached": 31.6,
         "piston_mass": 0.76, "eft_drop": 1.58, "eft_3b_spool": 10.0, "spool_28": 28.0, "fig9a_tracking": 1.0,
         "T_ld_final": 11.2, "zeta_free": None, "eft_4b_drop": None}

#: rows the calibrated model reproduces (each checks physics against the paper's statement)
AGREE = ("natural_frequency", "zeta_free", "friction_free", "zeta_attached", "friction_attached",
         "natural_frequency_free_vibration", "equivalent_damping", "gp_falls_with_mass", "gp_used_stable",
         "T_ld_estimate", "undercompensated_6ms", "force_direct", "substructure_140kg", "table1_stability",
         "eft_drop", "piston_mass", "flow_curve",
         # Figs 3(b), 4(b, c) and the EFT delay compensation (methods.run_eft)
         "eft_3b_shallow", "eft_3b_band", "eft_4b_drop", "eft_4b_flow_model", "eft_4c_nonlinear", "eft_under",
         "eft_over", "eft_over_unstable",
         # Figs 8-10(a) (methods.run_rpsd)
         "sim_undercompensated_6ms", "fig9a_structural", "fig9a_tracking", "fig10a_force_vs_kx",
         "fig10a_force_vs_input")

SUBSET = ("structure", "force", "eft", "gain_bound", "rpsd_linear", "rpsd", "table1")


def _num(v) -> float:
    return {"inf": math.inf, "-inf": -math.inf, "nan": math.nan}.get(v, v) if isinstance(v, str) else float(v)


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    out = tmp_path_factory.mktemp("repro")
    rep = rp.reproduce(out, quick=True, sections=SUBSET, progress=False, workers=2)
    return out, rep


def test_rows_check_against_paper_values(table):
    out, rep = table
    data = json.loads((out / "reproduction.json").read_text())
    rows = {r["key"]: r for r in data["rows"]}
    assert len(rows) == len(data["rows"])  # keys are unique
    for key, paper in PAPER.items():
        r = rows[key]
        if paper is not None:
            assert r["paper_value"] == pytest.approx(paper)
    for r in data["rows"]:
        lo, hi, v = _num(r["lo"]), _num(r["hi"]), _num(r["our_value"])
        # The verdict follows from the stated tolerance, and the tolerance contains the paper's value.
        assert r["agree"] == (lo <= v <= hi), r["key"]
        if r["paper_value"] is not None:
            assert lo <= r["paper_value"] <= hi, r["key"]
        # Every disagreement is explained.
        if not r["agree"]:
            assert len(r["why"]) > 40, r["key"]
    for key in AGREE:
        assert rows[key]["agree"], rows[key]


def test_fig8a_spool_row_names_its_run(table):
    """The 28 % row says which of our runs it reports (the 0.15 g, 6 ms sweep) and its opening."""
    _, rep = table
    r = next(r for r in rep.rows if r.key == "spool_28")
    assert "0.15 g" in r.ours and "6 ms" in r.ours and "28 % passed" in r.ours
    assert 0.0 < r.our_value <= 100.0


def test_markdown_and_figures(table):
    out, rep = table
    md = (out / "reproduction.md").read_text()
    assert f"{rep.agree_count} of {len(rep.rows)} rows agree" in md
    assert md.count("\n| ") == len(rep.rows) + 1
    for f in rep.figures:
        assert f.exists() and f.stat().st_size > 10_000
    assert {"fig2b_free_vibration.png", "fig3b_compensated_eft.png", "fig4a_flow_curve.png",
            "fig4b_eft_8.9kN_linear.png", "fig4c_eft_8.9kN_nonlinear.png", "fig6b_max_gain_vs_mass.png",
            "fig8a_rpsd_6ms.png", "fig8b_rpsd_16ms.png", "fig8_damping_vs_T_ld.png", "fig9_free_vibration_rpsd.png",
            "fig10a_force_vs_restoring.png", "fig10b_pole_zero.png"} <= {f.name for f in rep.figures}
    # The table follows the section order, whichever worker finished first.
    keys = [r.key for r in rep.rows]
    assert keys.index("eft_3b_shallow") < keys.index("gp_falls_with_mass") < keys.index("spool_28")


def test_workers_do_not_change_the_table(tmp_path):
    serial = rp.reproduce(tmp_path / "a", sections=("rpsd_linear", "table1"), progress=False, workers=1)
    pooled = rp.reproduce(tmp_path / "b", sections=("rpsd_linear", "table1"), progress=False, workers=2)
    assert [(r.key, r.our_value) for r in serial.rows] == [(r.key, r.our_value) for r in pooled.rows]


def test_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match="section"):
        rp.reproduce(tmp_path, sections=("nope",), progress=False)
    with pytest.raises(ValueError, match="workers"):
        rp.reproduce(tmp_path, sections=("table1",), progress=False, workers=0)


def test_linear_rows_paper_numbers():
    """Eq (13), Fig 6a rows (cheap: the linear part of the displacement section)."""
    import servohydraulics as sh
    from servohydraulics import analysis as an

    rig = sh.zhao2003()
    assert abs(an.omega_cRPD(rig) / (2 * math.pi) - 1.96) <= 0.02
    assert abs(1e3 / an.omega_cRPD(rig) - 81.0) <= 1.0
    T, _ = an.amplitude_compensation_T(an.G_xu(an.linear_analysis_rig(rig)) * an.zoh_delay(5e-4))
    assert abs(1e3 * T - 68.0) <= 3.0


def test_the_package_exports_the_driver():
    """``sh.reproduce`` is the paper driver; the old top-level re-export modules are gone (one path)."""
    import servohydraulics as sh

    assert sh.reproduce is rp.reproduce
    assert list(rp.SECTIONS)
    for old in ("servohydraulics.reproduce", "servohydraulics.demo"):
        with pytest.raises(ModuleNotFoundError):
            importlib.import_module(old)


def test_every_section_has_its_claims_with_unique_keys():
    from servohydraulics.paper.claims import CLAIMS

    assert list(CLAIMS) == list(rp.SECTIONS)
    keys = [c.key for claims in CLAIMS.values() for c in claims]
    assert len(keys) == len(set(keys)) == 53
