"""A synthetic maRTHS data folder (the benchmark's file layout, not its data) for the tests that must run
without ``../shared/marths-data``: the nominal zero-pole-gain plant, RoDeAC parameters of the benchmark's
size, a stiff 29-DOF chain with massless DOFs, a Joint_DOF.xlsx and three short ground motions."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from servohydraulics import _core

N_DOF = 29
INFLUENCE_DOFS = (13, 26, 27)


def chain(n: int = N_DOF) -> tuple[np.ndarray, np.ndarray]:
    """K [N/m], M [kg] of a stiff chain, every third DOF massless (the FE model's kind: M singular)."""
    K = np.diag(np.full(n, 3e8)) - np.diag(np.full(n - 1, 1e8), 1) - np.diag(np.full(n - 1, 1e8), -1)
    M = np.diag([0.0 if i % 3 == 1 else 2e5 for i in range(n)])
    return K, M


def write_xlsx(path: Path, column_b: list[int]) -> None:
    """A minimal workbook whose first sheet has a text header row and column B = ``column_b``."""
    rows = ['<row r="1"><c r="A1" t="inlineStr"><is><t>Joint</t></is></c>'
            '<c r="B1" t="inlineStr"><is><t>Ux</t></is></c></row>']
    for i, v in enumerate(column_b, start=2):
        rows.append(f'<row r="{i}"><c r="A{i}"><v>{i - 1}</v></c><c r="B{i}"><v>{v}</v></c></row>')
    sheet = ('<?xml version="1.0" encoding="UTF-8"?><worksheet xmlns="http://schemas.openxmlformats.org/'
             'spreadsheetml/2006/main"><sheetData>' + "".join(rows) + "</sheetData></worksheet>")
    ct = ('<?xml version="1.0" encoding="UTF-8"?><Types xmlns="http://schemas.openxmlformats.org/package/2006/'
          'content-types"><Default Extension="rels" ContentType="application/vnd.openxmlformats-package.'
          'relationships+xml"/><Default Extension="xml" ContentType="application/xml"/><Override PartName="/xl/'
          'workbook.xml" ContentType="application/vnd.openxmlformats-officedocument.spreadsheetml.sheet.main+xml"/>'
          '<Override PartName="/xl/worksheets/sheet1.xml" ContentType="application/vnd.openxmlformats-'
          'officedocument.spreadsheetml.worksheet+xml"/></Types>')
    rels = ('<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/'
            '2006/relationships"><Relationship Id="rId1" Type="http://schemas.openxmlformats.org/officeDocument/2006/'
            'relationships/officeDocument" Target="xl/workbook.xml"/></Relationships>')
    wb = ('<?xml version="1.0" encoding="UTF-8"?><workbook xmlns="http://schemas.openxmlformats.org/spreadsheetml/'
          '2006/main" xmlns:r="http://schemas.openxmlformats.org/officeDocument/2006/relationships"><sheets>'
          '<sheet name="Sheet1" sheetId="1" r:id="rId1"/></sheets></workbook>')
    wbrels = ('<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/'
              '2006/relationships"><Relationship Id="rId1" Type="http://schemas.openxmlformats.org/officeDocument/'
              '2006/relationships/worksheet" Target="worksheets/sheet1.xml"/></Relationships>')
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("[Content_Types].xml", ct)
        z.writestr("_rels/.rels", rels)
        z.writestr("xl/workbook.xml", wb)
        z.writestr("xl/_rels/workbook.xml.rels", wbrels)
        z.writestr("xl/worksheets/sheet1.xml", sheet)


def ground_motion(duration: float = 2.0, dt: float = 0.01, seed: int = 0) -> np.ndarray:
    """2 x n (time, acceleration [m/s^2]): 0.5 s of zeros, a decaying burst, 0.5 s of zeros."""
    t = np.arange(int(round((duration + 1.0) / dt)) + 1) * dt
    rng = np.random.default_rng(seed)
    a = np.where((t > 0.5) & (t < 0.5 + duration), 4.0 * np.sin(2 * np.pi * 2.5 * t + rng.uniform(0, 1))
                 * np.exp(-(t - 0.5)), 0.0)
    return np.vstack([t, a])


def write_folder(folder: Path, duration: float = 2.0) -> Path:
    import scipy.io as sio

    folder = Path(folder)
    fe = folder / "FE_Model" / "REF_SAP2000_Model"
    fe.mkdir(parents=True, exist_ok=True)
    ss = _core.marths.BenchmarkPlantModel().transfer_matrix().realize()
    (folder / "ID_Control_plant_100Hz_plantFRAME_SS.json").write_text(
        json.dumps({k: np.asarray(getattr(ss, k)).tolist() for k in "ABCD"}))
    theta = np.array([[5.41470353], [1.96280665], [-1.50482526], [-4.9577638]])
    P = 1e5 * np.eye(4) - 3e4 * (np.eye(4, k=1) + np.eye(4, k=-1))
    sio.savemat(folder / "Initial_parameters.mat", {"theta0_1": theta, "theta0_2": 1.1 * theta,
                                                    "P0_1": P, "P0_2": 0.8 * P})
    K, M = chain()
    np.savetxt(fe / "K_matrix.csv", K, delimiter=",", fmt="%.15g")
    np.savetxt(fe / "M_matrix.csv", M, delimiter=",", fmt="%.15g")
    write_xlsx(fe / "Joint_DOF.xlsx", [0, 0, 13, 0, 26, 27, 27, 0])
    for i, (fname, var) in enumerate((("ElCentroAccelNoScaling.mat", "ElCentroAccel"),
                                      ("KobeAccelNoScaling.mat", "KobeAccel"),
                                      ("MorganAccelNoScaling.mat", "MorganAccel"))):
        sio.savemat(folder / fname, {var: ground_motion(duration, seed=i)})
    return folder


def run_cli(capsys, *argv) -> tuple[int, str, str]:
    """``servohydraulics ARGV`` in process: (exit code, stdout, stderr)."""
    from servohydraulics.cli import main

    code = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def assert_refused(capsys, tmp_path, argv, named) -> None:
    """``marths-benchmark ARGV`` ends in ``error:`` naming every part of ``named``, exit 2, no
    traceback, nothing written to its --out."""
    out = tmp_path / "never"
    code, _, err = run_cli(capsys, "marths-benchmark", *argv, "--quiet", "--out", out)
    assert code == 2, err
    assert err.startswith("servohydraulics marths-benchmark: error: "), err
    assert "Traceback" not in err
    for part in named:
        assert part in err, err
    assert not out.exists()
