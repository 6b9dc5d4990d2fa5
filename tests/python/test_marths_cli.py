"""``servohydraulics marths-benchmark`` end to end on a synthetic data folder (the benchmark's layout,
marths_support.py), and bad input: a missing or corrupt file, an unknown record or controller, a perturbed
count that is not a whole number each give ``error: ...`` naming the file or the field and the value, exit
code 2, no traceback and nothing in ``--out``; a hypothesis suite draws defects in the data folder."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.io as sio
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from marths_support import assert_refused, run_cli, write_folder, write_xlsx

from servohydraulics import marths

FE = Path("FE_Model") / "REF_SAP2000_Model"


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    return write_folder(tmp_path_factory.mktemp("marths-cli") / "data")


@pytest.fixture
def folder(pristine, tmp_path):
    return Path(shutil.copytree(pristine, tmp_path / "data"))



def test_the_command_writes_results_report_and_plots(folder, tmp_path, capsys):
    out = tmp_path / "out"
    code, stdout, err = run_cli(capsys, "marths-benchmark", "--data", folder, "--record", "morgan", "--controller",
                             "rodeac", "--perturbed", "2", "--workers", "1", "--quiet", "--out", out)
    assert code == 0, err
    res = json.loads((out / "results.json").read_text())
    nom = res["runs"]["nominal"]
    assert list(nom["J"]) == [f"J{i}" for i in range(1, 11)]
    assert [len(v) for v in nom["J"].values()] == [2, 2, 2, 2, 2, 2, 2, 4, 2, 4]
    assert nom["J"]["J4"] == nom["J"]["J1"]
    assert isinstance(nom["realizable"], bool) and len(nom["peak_voltage_V"]) == 2
    assert nom["J_rounded"]["J2"][0] == round(nom["J"]["J2"][0], 1)
    p = res["runs"]["perturbed"]
    assert p["runs"] == 2 and len(p["trials"]) == 2 and set(p["J_mean"]) == set(nom["J"])
    assert nom["stable"] is True and p["stable"] == 2 and p["ran_to_end"] == 2
    assert res["meta"]["record"] == "morgan" and res["meta"]["seed"] == 123
    report = (out / "report.md").read_text()
    assert report.startswith("# Multi-axial RTHS benchmark (maRTHS): morgan")
    assert "NRMS tracking error" in report and "max peak error of the upper stories vs the reference" in report
    for png in ("tracking.png", "tracking_error.png", "synchronisation.png"):
        assert (out / png).stat().st_size > 1000
        assert f"]({png})" in report
    assert "J10 | max peak error" in stdout


class UserController:
    """No compensation, from a user's module."""

    def reset(self):
        pass

    def command(self, desired, measured):
        return desired


def test_a_users_controller_by_module_and_class(folder, tmp_path, capsys, monkeypatch):
    (tmp_path / "mine.py").write_text("class Plain:\n    '''mine'''\n    def reset(self):\n        pass\n"
                                      "    def command(self, desired, measured):\n        return desired\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    code, _, err = run_cli(capsys, "marths-benchmark", "--data", folder, "--controller", "mine:Plain", "--quiet",
                        "--out", tmp_path / "o")
    assert code == 0, err
    res = json.loads((tmp_path / "o" / "results.json").read_text())
    none = marths.run_trial(marths.load_data(folder), marths.load_record(folder, "elcentro"), "none")
    assert res["runs"]["nominal"]["J"] == none.J
    assert res["meta"]["controller"] == "mine:Plain"



@pytest.mark.parametrize("argv, named", [
    (["--record", "northridge"], ["invalid record = 'northridge'", "elcentro"]),
    (["--controller", "pid"], ["invalid controller = 'pid'", "rodeac"]),
    (["--controller", "nosuchmodule:X"], ["invalid controller = 'nosuchmodule:X'", "not found"]),
    (["--perturbed", "1.5"], ["invalid --perturbed = '1.5': expected a whole number >= 0"]),
    (["--perturbed", "-2"], ["invalid --perturbed = '-2'"]),
    (["--perturbed", "two"], ["invalid --perturbed = 'two'"]),
    (["--workers", "0"], ["invalid --workers = 0"]),
    (["--seed", "-1"], ["invalid --seed = -1"]),
], ids=["record", "controller", "module", "perturbed_fraction", "perturbed_negative", "perturbed_text", "workers",
        "seed"])
def test_bad_arguments_are_named(folder, tmp_path, capsys, argv, named):
    assert_refused(capsys, tmp_path, ["--data", folder, *argv], named)


def test_a_missing_folder_is_named(tmp_path, capsys):
    assert_refused(capsys, tmp_path, ["--data", tmp_path / "nowhere"], ["invalid data =", "not a directory"])


# ----------------------------------------------------------------------------- corrupt files

def _csv(path: Path, a: np.ndarray) -> None:
    np.savetxt(path, a, delimiter=",", fmt="%.15g")


def _defects():
    """(name, relative file, action(folder), words of the message)"""
    def K(f):
        return np.loadtxt(f / FE / "K_matrix.csv", delimiter=",")

    def plant(f):
        return json.loads((f / "ID_Control_plant_100Hz_plantFRAME_SS.json").read_text())

    def set_plant(f, d):
        (f / "ID_Control_plant_100Hz_plantFRAME_SS.json").write_text(json.dumps(d))

    def asym(f):
        k = K(f)
        k[3, 7] += 1e6
        _csv(f / FE / "K_matrix.csv", k)

    def nan_k(f):
        (f / FE / "K_matrix.csv").write_text((f / FE / "K_matrix.csv").read_text().replace("3e+08", "nan", 1)
                                             .replace("300000000", "nan", 1))

    def text_m(f):
        lines = (f / FE / "M_matrix.csv").read_text().splitlines()
        lines[4] = "abc," + lines[4].split(",", 1)[1]
        (f / FE / "M_matrix.csv").write_text("\n".join(lines))

    def m_size(f):
        _csv(f / FE / "M_matrix.csv", np.eye(28))

    def neg_m(f):
        _csv(f / FE / "M_matrix.csv", -np.eye(29))

    def ragged(f):
        d = plant(f)
        d["A"][2] = d["A"][2][:3]
        set_plant(f, d)

    def d_nonzero(f):
        d = plant(f)
        d["D"][0][1] = 0.3
        set_plant(f, d)

    def unstable(f):
        d = plant(f)
        d["A"][0][0] = 5.0
        set_plant(f, d)

    def b_shape(f):
        d = plant(f)
        d["B"] = [row[:1] for row in d["B"]]
        set_plant(f, d)

    def p_asym(f):
        m = sio.loadmat(f / "Initial_parameters.mat")
        m["P0_2"][0, 3] += 5.0
        sio.savemat(f / "Initial_parameters.mat", {k: v for k, v in m.items() if not k.startswith("__")})

    def theta_nan(f):
        m = sio.loadmat(f / "Initial_parameters.mat")
        m["theta0_1"][2, 0] = np.nan
        sio.savemat(f / "Initial_parameters.mat", {k: v for k, v in m.items() if not k.startswith("__")})

    def no_theta(f):
        m = sio.loadmat(f / "Initial_parameters.mat")
        sio.savemat(f / "Initial_parameters.mat", {k: v for k, v in m.items() if k in ("theta0_1", "P0_1", "P0_2")})

    def dof_40(f):
        write_xlsx(f / FE / "Joint_DOF.xlsx", [0, 13, 40])

    def rec_rows(f):
        sio.savemat(f / "ElCentroAccelNoScaling.mat", {"ElCentroAccel": np.zeros((3, 50))})

    def rec_nan(f):
        m = sio.loadmat(f / "ElCentroAccelNoScaling.mat")["ElCentroAccel"]
        m[1, 30] = np.nan
        sio.savemat(f / "ElCentroAccelNoScaling.mat", {"ElCentroAccel": m})

    json_f, ini, k, m, x, rec = ("ID_Control_plant_100Hz_plantFRAME_SS.json", "Initial_parameters.mat",
                                 FE / "K_matrix.csv", FE / "M_matrix.csv", FE / "Joint_DOF.xlsx",
                                 "ElCentroAccelNoScaling.mat")
    return [
        ("K_asymmetric", k, asym, ["K: must be symmetric; entry [4,8] = 1000000 but [8,4] = 0"]),
        ("K_nan", k, nan_k, ["must be finite"]),
        ("M_text", m, text_m, ["line 5", "is not a number"]),
        ("M_size", m, m_size, ["M must be 29 x 29"]),
        ("M_negative", m, neg_m, ["M must be positive semi-definite"]),
        ("plant_ragged", json_f, ragged, ["A: not a numeric matrix"]),
        ("plant_D", json_f, d_nonzero, ["D[1,2] = 0.3"]),
        ("plant_unstable", json_f, unstable, ["must be stable"]),
        ("plant_B", json_f, b_shape, ["B must be 8 x 2"]),
        ("P0_asymmetric", ini, p_asym, ["P0_2: must be symmetric"]),
        ("theta_nan", ini, theta_nan, ["theta0_1: entry [2, 0] = nan: must be finite"]),
        ("theta_missing", ini, no_theta, ["variable 'theta0_2' missing"]),
        ("dof_40", x, dof_40, ["cell B4 = 40.0: must be a DOF number 1 to 29"]),
        ("record_rows", rec, rec_rows, ["must be 2 rows (time, acceleration)"]),
        ("record_nan", rec, rec_nan, ["acceleration: entry [30] = nan"]),
    ]


@pytest.mark.parametrize("name, rel, action, named", _defects(), ids=[d[0] for d in _defects()])
def test_a_corrupt_file_is_named(folder, tmp_path, capsys, name, rel, action, named):
    action(folder)
    assert_refused(capsys, tmp_path, ["--data", folder], [f"error: {folder / rel}", *named])


FILES = [str(p) for p in marths.FILES.values()] + ["ElCentroAccelNoScaling.mat"]


@pytest.mark.parametrize("rel", FILES)
def test_a_missing_file_is_named(folder, tmp_path, capsys, rel):
    (folder / rel).unlink()
    assert_refused(capsys, tmp_path, ["--data", folder], [f"error: {folder / rel}: file not found"])


GARBAGE = [b"", b"\x00" * 64, b"MATLAB 5.0 MAT-file" + b"\x00" * 200, b"PK\x03\x04 not a zip", b"{not json",
           "π,1\n".encode("utf-16"), b"1,2,3\n4,5\n"]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rel=st.sampled_from(FILES), content=st.one_of(st.sampled_from(GARBAGE), st.binary(max_size=300)),
       truncate=st.booleans())
def test_drawn_defects_in_the_data_folder_are_named(pristine, tmp_path_factory, rel, content, truncate):
    """Any file of the folder replaced by garbage (or cut short): a ValueError naming that file, never a crash,
    a hang or a silently wrong model."""
    folder = Path(shutil.copytree(pristine, tmp_path_factory.mktemp("drawn") / "data"))
    path = folder / rel
    if truncate:
        raw = path.read_bytes()
        path.write_bytes(raw[: len(content) % max(1, len(raw))])
    else:
        path.write_bytes(content)
    try:
        marths.prepare(folder, "elcentro", "rodeac")
    except ValueError as e:
        assert str(path) in str(e), str(e)
    else:  # a cut that kept a valid file (e.g. the CSV's complete first lines cannot be: a square 29 x 29 is needed)
        assert truncate


def test_the_cli_module_imports_light():
    """Registering the command (every CLI start) imports neither SciPy nor matplotlib."""
    import subprocess

    code = ("import sys; import servohydraulics.commands.marths_benchmark as m; import argparse; "
            "p = argparse.ArgumentParser(); m.register(p.add_subparsers()); "
            "print('scipy' in sys.modules, 'matplotlib' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
