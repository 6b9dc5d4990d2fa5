"""Record files a lab has (issue 25, item 4): delimiters, decimal commas, units and scales,
column mappings, MATLAB files, raw data-acquisition exports with a header block; every bad
input an error naming the file, the column or field and the value.

Oracles: the same record written in every layout reads back to the same SI values (to the
digits written); the UTFSM CSVs are reproduced from the lab's two raw DAQ files with the
README's scales and offset rule, to the CSVs' printed resolution."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest
from shared_data import shared_path

import servohydraulics as sh
from servohydraulics.readers import Layout, load_layout

N = 400
DT = 1e-3


def _channels(n: int = N, dt: float = DT) -> dict[str, np.ndarray]:
    t = np.arange(n) * dt
    u = 0.002 * np.sin(2 * np.pi * 3.0 * t)
    return {"time": t, "command": u, "displacement": 0.98 * np.sin(2 * np.pi * 3.0 * t - 0.1) * 0.002,
            "force": 1500.0 * np.cos(2 * np.pi * 3.0 * t)}


def _write(path, header: list[str], cols: list[np.ndarray], delimiter: str = ",", decimal: str = ".",
           pre: str = "", fmt: str = "{:.9g}"):
    rows = []
    for k in range(cols[0].size):
        cells = [fmt.format(c[k]) for c in cols]
        if decimal == ",":
            cells = [c.replace(".", ",") for c in cells]
        rows.append(delimiter.join(cells))
    path.write_text(pre + delimiter.join(header) + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def _same(rec, ref: dict, rtol: float = 1e-8) -> None:
    for k, v in ref.items():
        np.testing.assert_allclose(rec.channels[k], v, rtol=rtol, atol=1e-12, err_msg=k)


@pytest.mark.parametrize("delimiter, decimal", [(",", "."), (";", "."), ("\t", "."), (" ", "."), (";", ","),
                                                ("\t", ","), (" ", ",")])
def test_delimiters_and_decimal_commas_read_the_same_record(tmp_path, delimiter, decimal):
    ref = _channels()
    path = _write(tmp_path / "r.txt", list(ref), list(ref.values()), delimiter, decimal)
    rec = sh.read_record(path)
    _same(rec, ref)
    assert rec.metadata["decimal"] == decimal


def test_units_scales_and_unit_headers_convert_to_si(tmp_path):
    ref = _channels()
    mm = _write(tmp_path / "mm.csv", ["time_ms", "command", "displacement", "force"],
                [1e3 * ref["time"], 1e3 * ref["command"], 1e3 * ref["displacement"], 1e-3 * ref["force"]])
    _same(sh.read_record(mm, units={"command": "mm", "displacement": "mm", "force": "kN"}), ref)
    head = _write(tmp_path / "head.csv", ["Time [ms]", "command (mm)", "displacement_mm", "Force [kN]"],
                  [1e3 * ref["time"], 1e3 * ref["command"], 1e3 * ref["displacement"], 1e-3 * ref["force"]])
    rec = sh.read_record(head)
    _same(rec, ref)
    assert rec.metadata["units"]["force"] == "kN"
    volts = _write(tmp_path / "v.csv", ["time", "command", "displacement", "force"],
                   [ref["time"], 100 * ref["command"], 100 * ref["displacement"], ref["force"] / 980.665])
    _same(sh.read_record(volts, units={"command": "mm", "displacement": "mm"},
                         scale={"command": 10, "displacement": 10, "force": 980.665}), ref)


def test_columns_mapping_and_a_file_without_names(tmp_path):
    ref = _channels()
    path = _write(tmp_path / "daq.csv", ["t", "u_cmd", "lvdt", "load", "temperature"],
                  [ref["time"], ref["command"], ref["displacement"], ref["force"], np.full(N, 21.0)])
    rec = sh.read_record(path, columns={"time": "t", "command": "u_cmd", "displacement": "lvdt", "force": "load"})
    _same(rec, ref)
    assert rec.metadata["ignored"] == ["temperature"]
    bare = tmp_path / "bare.csv"
    bare.write_text("\n".join(",".join(f"{c[k]:.9g}" for c in ref.values()) for k in range(N)) + "\n")
    _same(sh.read_record(bare, columns={"time": "1", "command": "2", "displacement": "3", "force": "4"}), ref)


@pytest.mark.parametrize("kwargs, words", [
    ({"columns": {"force": "F"}}, ["bad.csv", "force='F' names no column", "header ['t', 'cmd', 'x', 'load']",
                                  "the mapping tried"]),
    ({"columns": {"forse": "load"}}, ["invalid columns channel = 'forse'", "not a record channel"]),
    ({}, ["bad.csv", "missing column(s) ['time', 'command', 'displacement', 'force']", "header ['t', 'cmd'",
          "--columns time=NAME"]),
    ({"columns": {"time": "t", "command": "cmd", "displacement": "x", "force": "load"},
      "units": {"displacement": "mmm"}}, ["bad.csv", "invalid unit of 'displacement' = 'mmm'", "known: m, mm"]),
    ({"columns": {"time": "t", "command": "cmd", "displacement": "x", "force": "load"},
      "units": {"force": "mm"}}, ["invalid unit of 'force' = 'mm'", "a m unit, but force is in N"]),
    ({"columns": {"time": "t", "command": "cmd", "displacement": "x", "force": "load"},
      "scale": {"force": "x"}}, ["invalid scale force = 'x'", "not a number"]),
    ({"columns": {"time": "t", "command": "cmd", "displacement": "x", "force": "load"},
      "scale": {"force": 0.0}}, ["invalid scale force = 0.0", "non-zero"]),
    ({"columns": {"time": "t", "command": "cmd", "displacement": "x", "force": "load"},
      "offset_first_s": 10.0}, ["bad.csv", "invalid offset_first_s = 10.0", "0.4 s long"]),
])
def test_column_and_unit_errors_show_the_header_and_the_mapping(tmp_path, kwargs, words):
    ref = _channels()
    path = _write(tmp_path / "bad.csv", ["t", "cmd", "x", "load"], list(ref.values()))
    with pytest.raises(ValueError) as e:
        sh.read_record(path, **kwargs)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_mixed_delimiters_and_decimal_marks_are_refused(tmp_path):
    ref = _channels()
    a = _write(tmp_path / "mixed.csv", list(ref), list(ref.values()), ",")
    a.write_text(a.read_text().replace(",", ";", 0).replace("\n", "\n", 1))
    lines = a.read_text().splitlines()
    lines[1:] = [ln.replace(",", ";") for ln in lines[1:]]
    a.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"mixed.csv: mixed or unknown delimiters: the header 'time,command,"
                                         r"displacement,force' splits into 4 field\(s\) by ','"):
        sh.read_record(a)
    lines[200] = lines[200].replace(";", ",")  # one row in the minority: its line is named
    lines[1:200] = [ln.replace(";", ",") for ln in lines[1:200]]
    lines[201:] = [ln.replace(";", ",") for ln in lines[201:]]
    lines[300] = lines[300].replace(",", ";")
    a.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"mixed.csv: could not parse row 301: 1 field\(s\), the header 4"):
        sh.read_record(a)
    b = _write(tmp_path / "marks.txt", list(ref), list(ref.values()), ";", ",")
    text = b.read_text().splitlines()
    text[5] = text[5].replace(",", ".")
    b.write_text("\n".join(text) + "\n")
    with pytest.raises(ValueError, match=r"marks.txt: mixed decimal marks: row \d+ has .*,.* and row 6"):
        sh.read_record(b)


# ----------------------------------------------------------------------------- MATLAB files

def _savemat(path, data):
    from scipy.io import savemat

    savemat(path, data)
    return path


def test_mat_files_vectors_struct_matrix_with_names(tmp_path):
    ref = _channels()
    _same(sh.read_record(_savemat(tmp_path / "vec.mat", {k: v[:, None] for k, v in ref.items()})), ref)
    _same(sh.read_record(_savemat(tmp_path / "st.mat", {"rec": {"time": ref["time"], "u": ref["command"],
                                                                 "displacement": ref["displacement"],
                                                                 "force": ref["force"]}, "current_A": 0.5}),
                         columns={"command": "rec.u"}), ref)
    m = np.column_stack(list(ref.values()))
    imp = _savemat(tmp_path / "imp.mat", {"data": m, "colheaders": np.array(["time", "command", "displacement",
                                                                              "force_kN"], dtype=object)})
    got = sh.read_record(imp)
    np.testing.assert_allclose(got.force, 1e3 * ref["force"])
    rows = _savemat(tmp_path / "rows.mat", {"M": m.T, "fs": 1000.0})  # channels x samples, no time vector
    got = sh.read_record(rows, columns={"command": "M(:,2)", "displacement": "M(:,3)", "force": "M(:,4)"})
    _same(got, {k: v for k, v in ref.items()})


@pytest.mark.parametrize("data, kwargs, words", [
    ({"time": np.arange(N) * DT, "command": np.ones(N)}, {},
     ["missing column(s) ['displacement', 'force']", "variables: time (400), command (400)"]),
    ({"M": np.ones((N, 3))}, {"columns": {"time": "M(:,1)", "command": "M(:,2)", "displacement": "M(:,3)",
                                          "force": "M(:,4)"}},
     ["invalid column 'M(:,4)'", "M has 3 channel(s)"]),
    ({"rec": {"t": np.arange(N) * DT}}, {"columns": {"force": "rec.F"}},
     ["force='rec.F' names no column", "rec.t (400)"]),
])
def test_mat_file_errors_name_the_variable(tmp_path, data, kwargs, words):
    path = _savemat(tmp_path / "bad.mat", data)
    with pytest.raises(ValueError) as e:
        sh.read_record(path, **kwargs)
    assert "bad.mat" in str(e.value)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_mat_v73_without_h5py_says_so(tmp_path, monkeypatch):
    path = tmp_path / "big.mat"
    path.write_bytes(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
                     .ljust(512, b" ") + b"\x89HDF\r\n\x1a\n" + bytes(64))
    monkeypatch.setitem(sys.modules, "h5py", None)
    with pytest.raises(ValueError, match=r"big.mat: a MATLAB v7.3 \(HDF5\) file: reading it needs h5py"):
        sh.read_record(path)


def test_mat_v73_through_h5py(tmp_path):
    """A v7.3 file as MATLAB writes it (an HDF5 file behind a 512-byte header, arrays stored
    column-major, a struct as a group, a cell array of names as references)."""
    h5py = pytest.importorskip("h5py")
    ref = _channels()
    path = tmp_path / "v73.mat"
    with h5py.File(path, "w", userblock_size=512) as f:
        g = f.create_group("rec")
        g.attrs["MATLAB_class"] = np.bytes_("struct")
        for k, v in ref.items():
            d = g.create_dataset(k, data=v[None, :])  # MATLAB's n x 1 column, stored transposed
            d.attrs["MATLAB_class"] = np.bytes_("double")
        d = f.create_dataset("fs", data=np.array([[1000.0]]))
        d.attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, HDF5 schema 1.00 .".ljust(128, b" "))
    rec = sh.read_record(path)
    _same(rec, ref)
    assert rec.metadata["format"] == "mat v7.3"


# ----------------------------------------------------------------------------- raw DAQ exports

def _daq(path, n: int = 2500, count: int | None = None, interval: float = DT, stamp_dt: float | None = None,
         truncate: bool = False, scale=(0.01, 9806.65, 0.01), offsets=(0.003, -0.02, 0.002)) -> dict:
    """A raw export in the UTFSM DAQ's layout (README 'Raw DAQ exports'); returns the SI channels
    the layout should give (offsets of the first second removed)."""
    import datetime as dt

    ref = _channels(n, DT)
    volts = {"CHANNEL0": ref["displacement"] / scale[0] + offsets[0], "CHANNEL1": ref["force"] / scale[1] + offsets[1],
             "CHANNEL2": ref["command"] / scale[2] + offsets[2]}
    volts = {k: np.round(v, 4) for k, v in volts.items()}  # the DAQ's 0.1 mV resolution
    t0 = dt.datetime(2022, 6, 29, 16, 5, 36, 674000)
    lines = ["Header Size:  7", "Version:  2", f"Sampling Interval:  {interval:g}",
             f"Sampling Rate:  {1 / interval:g}", f"Sample Count:  {n if count is None else count}",
             "Device Serial Number:  0", "Sample Number, Date/Time, CHANNEL0, CHANNEL1, CHANNEL2, Events"]
    sdt = DT if stamp_dt is None else stamp_dt
    for k in range(n):
        stamp = (t0 + dt.timedelta(seconds=k * sdt)).strftime("%m/%d/%Y %I:%M:%S.%f")[:-3] + " PM"
        row = (f"{k + 1:>10},   {stamp}, {volts['CHANNEL0'][k]:.4f}, {volts['CHANNEL1'][k]:.4f}, "
               f"{volts['CHANNEL2'][k]:.4f}")
        row += ", DAQ Start" if k == 0 else (", DAQ Pause, DAQ Stop" if k == n - 1 else "")
        lines.append(row)
    text = "\r\n".join(lines) + "\r\n"
    if truncate:
        text = text[: text.rindex(",", 0, len(text) - 30)]
    path.write_text(text)
    m = 1000
    expect = {"time": ref["time"]}
    for ch, col, s in (("displacement", "CHANNEL0", scale[0]), ("force", "CHANNEL1", scale[1]),
                       ("command", "CHANNEL2", scale[2])):
        v = volts[col] * s
        expect[ch] = v - v[:m].mean()
    return expect


LAYOUT = Layout(columns={"time": "Sample Number", "command": "CHANNEL2", "displacement": "CHANNEL0",
                         "force": "CHANNEL1"},
                units={"time": "samples", "command": "mm", "displacement": "mm"},
                scale={"command": 10.0, "displacement": 10.0, "force": 9806.65}, header_lines=7,
                sample_interval="Sampling Interval", sample_count="Sample Count", timestamps="Date/Time",
                offset_first_s=1.0)


def test_raw_daq_export_read_with_a_layout(tmp_path):
    expect = _daq(tmp_path / "run.txt")
    rec = sh.read_record(tmp_path / "run.txt", LAYOUT)
    _same(rec, expect, rtol=1e-9)
    assert rec.metadata["metadata"]["Sample Count"] == "2500"
    assert set(rec.metadata["offsets"]) == {"command", "displacement", "force"}
    # the same from the committed layout file, and found without header_lines
    lay = load_layout(os.path.join(os.path.dirname(__file__), "..", "..", "examples", "layouts",
                                   "utfsm_daq_2022-06.toml"))
    _same(sh.read_record(tmp_path / "run.txt", lay), expect, rtol=1e-9)
    _same(sh.read_record(tmp_path / "run.txt", lay, header_lines=None), expect, rtol=1e-9)


@pytest.mark.parametrize("case, words", [
    ("truncated", ["run.txt", "could not parse row 2507: 4 field(s), the header 6", "truncated"]),
    ("count", ["run.txt", "invalid header 'Sample Count' = '3000': the file has 2500 data rows",
               "the file is truncated or the header is wrong"]),
    ("stamps", ["run.txt", "time stamps 'Date/Time' disagree with the sample interval 0.001 s"]),
    ("rate", []),
])
def test_raw_daq_errors(tmp_path, case, words):
    path = tmp_path / "run.txt"
    if case == "truncated":
        _daq(path, truncate=True)
    elif case == "count":
        _daq(path, count=3000)
    elif case == "stamps":
        _daq(path, stamp_dt=2e-3)
    else:  # the interval says 0.002 s, the rate 1000 Hz
        _daq(path, interval=2e-3)
        path.write_text(path.read_text().replace("Sampling Rate:  500", "Sampling Rate:  1000"))
        words = ["run.txt", "invalid header 'Sampling Interval' = '0.002'", "'Sampling Rate' is '1000'"]
    with pytest.raises(ValueError) as e:
        sh.read_record(path, LAYOUT)
    for w in words:
        assert w in str(e.value), str(e.value)


@pytest.mark.parametrize("text, words", [
    ("bogus = 1\n", ["lay.toml", "unknown key(s) ['bogus']"]),
    ("header_lines = -1\n", ["lay.toml", "invalid header_lines = -1"]),
    ("[columns]\nforse = 'F'\n", ["lay.toml", "invalid columns channel = 'forse'"]),
    ("[scale]\nforce = 'big'\n", ["lay.toml", "invalid scale force = 'big'"]),
    ("offset_first_s = -1\n", ["lay.toml", "invalid offset_first_s = -1"]),
    ("delimiter = '|'\n", ["lay.toml", "invalid delimiter = '|'"]),
    ("header_lines = [\n", ["lay.toml", "not a valid TOML layout"]),
])
def test_layout_file_errors(tmp_path, text, words):
    (tmp_path / "lay.toml").write_text(text)
    with pytest.raises(ValueError) as e:
        load_layout(tmp_path / "lay.toml")
    for w in words:
        assert w in str(e.value), str(e.value)


# ----------------------------------------------------------------------------- the UTFSM raw files

UTFSM = "real-data/utfsm-mts-mrdamper"


@pytest.mark.parametrize("raw, csv, layout, offsets", [
    ("2022-06-29_chirp20Hz_0A.txt", "chirp20Hz_0A.csv", "utfsm_daq_2022-06.toml", (-0.02916, -0.02400, -0.02091)),
    ("2022-05-25_sweep15Hz_0p5A.txt", "sweep15Hz_0p5A.csv", "utfsm_daq_2022-05.toml", (0.00421, 0.00306, 0.00215)),
])
def test_utfsm_raw_daq_files_reproduce_the_shared_csvs(raw, csv, layout, offsets):
    """The README's rule (scales 10 mm/V, 9806.65 or 980.665 N/V, each channel's first-second mean
    removed) applied by the layout file to the raw export gives the shared CSV to its printed
    resolution (6 significant digits in m, 0.1 N), and the offsets the README lists (in V)."""
    lay = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "layouts", layout)
    rec = sh.read_record(shared_path(f"{UTFSM}/raw/{raw}"), layout=lay)
    ref = sh.read_record(shared_path(f"{UTFSM}/{csv}"))
    assert len(rec) == len(ref)
    np.testing.assert_allclose(rec.time, ref.time, rtol=0, atol=1e-12)
    for ch in ("command", "displacement", "force"):
        c = ref.channels[ch]
        # the CSV prints m with 6 significant digits (%.5e) and N to 0.1 N: half its last digit
        half = 0.05 * np.ones_like(c) if ch == "force" else \
            0.5 * 10.0 ** (np.floor(np.log10(np.maximum(np.abs(c), 1e-30))) - 5)
        diff = np.abs(rec.channels[ch] - c)
        assert np.all(diff <= half * (1 + 1e-6) + 1e-15), f"{ch}: {diff.max()} at {np.argmax(diff - half)}"
    scales = {"displacement": 0.01, "force": 9806.65 if "06" in layout else 980.665, "command": 0.01}
    got = [rec.metadata["offsets"][c] / scales[c] for c in ("displacement", "force", "command")]
    np.testing.assert_allclose(got, offsets, atol=5e-6)  # the README prints them to 0.01 mV
