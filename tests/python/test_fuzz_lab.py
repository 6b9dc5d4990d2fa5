"""Property tests of ``identify`` and ``compare`` on the command line (issue 26,
docs/robustness.md): drawn records (length, rate, noise, NaN/inf, non-uniform,
duplicate or reversed times, constant signals, missing columns, huge values),
drawn rigs (a TOML value replaced, a missing or empty file) and drawn flags;
and (issue 25) drawn record files: CSV, semicolon with decimal commas, tab,
whitespace, .mat vectors and structs, a DAQ export with a layout file, in m,
mm or inches and N or kN, with units in the header or given by ``--units``,
truncated, with a lying sample count, mixed delimiters or a missing variable,
and drawn reader flags (bad units, scales, columns, ``--accept``).

Every invocation ends in exit 0 with the whole output set, or one ``error:``
line that names a field and its value (or the input file), exit 2 (1 for a run
that fails), no output file; never an internal error, a traceback or a hang.
Where a reference exists the answer is checked against it: ``compare`` of a
record the rig itself simulated gives ~0 NRMSE, and ``identify`` from that rig
stays there; an identification never ends worse than its start and its
correlation matrix is symmetric with |corr| <= 1.

The default example counts keep both properties to a few tens of seconds (most
drawn inputs are refused at once; an accepted one costs 1-3 s, mostly the
plots); ``-m slow`` runs the heavier draws."""

from __future__ import annotations

import json
import math
import re
import signal
import subprocess
import sys
import uuid
from pathlib import Path

import numpy as np
import pytest
from cli_cases import run_case
from fuzz_support import COUNT, Tally, counted
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import servohydraulics as sh

OUTCOMES = Tally()
DT = 2e-3  #: the reference records' sample time [s]
N = 1000  #: the reference records' samples
BOUND_S = 90.0  #: wall-time bound of one invocation [s] (an accepted one takes a few seconds)
COMPARE_FILES = ("comparison.json", "overlay.png", "frf.png")
IDENTIFY_FILES = ("rig_identified.toml", "identification.json", "report.md")
#: a message names a field and its value (``invalid dt = 0.0: ...``), argparse's ``argument --x: invalid``,
#: or the input file (a record or rig file, a column of it)
NAMED = re.compile(r"invalid [^=\n]{1,80}? = \S|argument --?[\w-]+: |rec_?\S*\.(csv|txt|mat)|rig_?\S*\.toml")


def teardown_module() -> None:
    OUTCOMES.report(__name__)


def _reference(mode: str) -> dict[str, np.ndarray]:
    """A band-limited noise command (0-20 Hz, stationary: a coherent H1) through the preset."""
    from scipy import signal as sig

    rng = np.random.default_rng(7)
    b, a = sig.butter(2, 20.0 * 2 * DT)
    u = sig.lfilter(b, a, rng.standard_normal(N))
    u *= (1e-3 if mode == "displacement" else 2e3) / np.std(u)
    res = sh.simulate(sh.zhao2003(), mode=mode, command=u, dt=DT)
    return {"time": np.arange(N) * DT, "command": u, "displacement": np.asarray(res.displacement),
            "force": np.asarray(res.force)}


_REFERENCES: dict[str, dict] = {}


def reference(mode: str) -> dict[str, np.ndarray]:
    if mode not in _REFERENCES:
        _REFERENCES[mode] = _reference(mode)
    return _REFERENCES[mode]


DEFECTS = ["none"] * 12 + ["nan", "inf", "jitter", "duplicate_time", "reversed", "swap_two",
           "constant_command", "constant_displacement", "constant_force", "missing_command",
           "missing_displacement", "missing_force", "missing_time", "huge", "huge_time", "header_only",
           "text_cell", "zero_time_step"]
COLUMNS = ("command", "displacement", "force")


def write_record(path: Path, mode: str, n: int, rate: float, noise: float, defect: str, column: str,
                 at: float) -> bool:
    """Writes a drawn record; True when it is the untouched reference (a record the preset simulated)."""
    ref = reference(mode)
    cols = {k: v[:n].copy() for k, v in ref.items()}
    cols["time"] = cols["time"] * rate
    rng = np.random.default_rng(n)
    for c in ("displacement", "force"):
        cols[c] = cols[c] + noise * np.std(ref[c]) * rng.standard_normal(n)
    i = min(int(at * n), n - 1)
    if defect in ("nan", "inf"):
        cols[column][i] = math.nan if defect == "nan" else -math.inf
    elif defect == "jitter":
        cols["time"] = cols["time"] + rng.uniform(0, 0.3, n) * DT * rate
    elif defect == "duplicate_time" and n > 1:
        cols["time"][i] = cols["time"][max(i - 1, 0)]
    elif defect == "zero_time_step" and n > 2:
        cols["time"][1:] = cols["time"][1:] - cols["time"][1]
    elif defect == "reversed":
        cols["time"] = cols["time"][::-1].copy()
    elif defect == "swap_two" and n > 2:
        j = min(i + 1, n - 1)
        cols["time"][[i, j]] = cols["time"][[j, i]]
    elif defect.startswith("constant_"):
        cols[defect.split("_", 1)[1]][:] = 1.0
    elif defect.startswith("missing_"):
        del cols[defect.split("_", 1)[1]]
    elif defect == "huge":
        cols[column] = cols[column] * 1e300
    elif defect == "huge_time":
        cols["time"] = cols["time"] + 1e300
    names = list(cols)
    rows = [] if defect == "header_only" else [",".join(repr(float(cols[k][r])) for k in names) for r in range(n)]
    if defect == "text_cell" and rows:
        rows[i] = rows[i].replace(",", ",abc", 1)
    path.write_text(",".join(names) + "\n" + "".join(r + "\n" for r in rows))
    return defect == "none" and noise == 0.0 and rate == 1.0


RIG_KEYS = ["m", "c", "k", "A", "K_v", "K_s", "f_v", "zeta_v", "p_s", "C_l", "K_a", "G_p", "x_v_max"]
RIG_VALUES = ["0", "-1", "nan", "inf", "1e300", "1e-300", '"x"', "[1]", "true", "2", "0.5"]


def write_rig(path: Path, change: str, key: str, value: str) -> bool:
    """Writes the preset with one drawn change; True when it is the preset itself."""
    if change == "missing":
        return False
    if change == "empty":
        path.write_text("")
        return False
    sh.save_rig(sh.zhao2003(), path)
    if change == "none":
        return True
    text = path.read_text()
    if change == "unknown":
        text = text.replace("[structure]\n", "[structure]\nbogus_key = 1.0\n", 1)
    elif re.search(rf"(?m)^{re.escape(key)} = ", text):
        old = float(re.search(rf"(?m)^{re.escape(key)} = (\S+)", text).group(1))
        new = repr(old * float(value)) if value in ("2", "0.5") else value
        text = re.sub(rf"(?m)^{re.escape(key)} = \S+", f"{key} = {new}", text, count=1)
    path.write_text(text)
    return False


def _alarm(signum, frame):
    raise TimeoutError(f"no answer within {BOUND_S} s")


def _run(argv: list[str]) -> tuple[str, int | None, str]:
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(int(BOUND_S))
    try:
        return run_case(argv)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _require(ok, kind: str, argv, detail) -> None:
    """Fails with ``kind`` first (the count mode tallies by it) and the invocation after."""
    if not ok:
        call = " ".join(Path(a).name if "/" in str(a) else str(a) for a in argv)
        text = f"{kind}: {' '.join(str(detail).split())[:300]} <- {call}"
        if COUNT:  # the tally keeps the first words; the whole case for the log
            print("\nVIOLATION", text)
        raise AssertionError(text)


def _check_outcome(argv, outcome, code, err, out: Path, files: tuple[str, ...]) -> None:
    OUTCOMES[outcome] += 1
    _require(outcome in ("ok", "error"), f"escaped {outcome}", argv, err)
    _require("Traceback" not in err and "internal error" not in err, "internal error", argv, err)
    left = sorted(p.name for p in out.iterdir()) if out.is_dir() else []
    _require(not [n for n in left if n.startswith(".")], "temporaries left", argv, left)
    if outcome == "ok":
        _require(set(files) <= set(left), "incomplete output set", argv, left)
        return
    _require(code in (1, 2), "exit code", argv, f"{code} {err}")
    _require(not [n for n in left if n in files or n.endswith(".png")], "partial output set", argv, f"{left} {err}")
    line = err.strip().splitlines()[-1] if err.strip() else ""
    _require("error: " in line or line.startswith("usage:"), "no error line", argv, err)
    words = [w for w in line.split("error: ", 1)[-1].split() if "/" not in w and not w.startswith(("rec_", "rig_"))]
    OUTCOMES[f"refused: {' '.join(words[:4])}"] += 1  # what refused it (SH_FUZZ_STATS=1 shows the tally)
    if code == 2:
        _require(NAMED.search(err), "unnamed message", argv, err)


def _paths(tmp_path: Path, record_mode, n, defect, column, rig_change, key, value) -> tuple[Path, Path, Path]:
    """Record, rig and output paths of one case, named after what was drawn (the log shows it)."""
    tag = uuid.uuid4().hex[:8]
    return (tmp_path / f"rec_{record_mode[0]}{n}_{defect}_{column}_{tag}.csv",
            tmp_path / f"rig_{rig_change}_{key}_{re.sub('[^a-z0-9]', '', value)}_{tag}.toml", tmp_path / f"out_{tag}")


FLOAT_FLAGS = ["0", "-0.001", "nan", "inf", "1e-9", "3e-4", "1e300", "x"]
METHODS = [None, None, None, "cvode", "rk4", "dopri5", "arkode_erk", "bogus"]


def _dt_flag(choice: str) -> str | None:
    return {"none": None, "record": repr(DT), "half": repr(DT / 2), "double": repr(2 * DT)}.get(choice, choice)


COMPARE_DRAW = dict(
    mode=st.sampled_from(["displacement", "force"]), record_mode=st.sampled_from(["displacement", "force"]),
    n=st.sampled_from([N, 1, 3, 50, 383, 384, 600]), rate=st.sampled_from([1.0, 1.0, 1.0, 0.5, 1e-6, 1e3]),
    noise=st.sampled_from([0.0, 0.0, 0.0, 0.01, 0.5]), defect=st.sampled_from(DEFECTS),
    column=st.sampled_from(("time",) + COLUMNS), at=st.floats(0, 1),
    rig_change=st.sampled_from(["none"] * 8 + ["value", "value", "unknown", "missing", "empty"]),
    key=st.sampled_from(RIG_KEYS), value=st.sampled_from(RIG_VALUES),
    dt=st.sampled_from(["none"] * 10 + ["record", "half", "double"] + FLOAT_FLAGS),
    method=st.sampled_from(METHODS))


def compare_case(tmp_path, mode, record_mode, n, rate, noise, defect, column, at, rig_change, key, value, dt,
                 method):
    """One drawn compare: a named error, or the whole output set, and ~0 NRMSE for the reference."""
    rec, rig, out = _paths(tmp_path, record_mode, n, defect, column, rig_change, key, value)
    exact = write_record(rec, record_mode, n, rate, noise, defect, column, at)
    exact &= write_rig(rig, rig_change, key, value) and record_mode == mode and dt in ("none", "record")
    argv = ["compare", str(rec), "--rig", str(rig), "--mode", mode, "--out", str(out)]
    argv += [f"--dt={_dt_flag(dt)}"] if _dt_flag(dt) is not None else []
    argv += ["--method", method] if method else []
    outcome, code, err = _run(argv)
    _check_outcome(argv, outcome, code, err, out, COMPARE_FILES)
    if outcome == "ok":
        data = json.loads((out / "comparison.json").read_text())
        for ch, m in data["channels"].items():
            _require(m["nrmse_pct"] is not None and math.isfinite(m["nrmse_pct"]), "non-finite NRMSE", argv, m)
            if exact and n >= 384:  # the record the rig itself simulated: no silent wrong answer
                OUTCOMES["compare: reference checked"] += 1
                _require(m["nrmse_pct"] < 1.0, "wrong answer", argv, f"{ch} NRMSE {m['nrmse_pct']} % on its own record")
    else:
        _require(not (exact and n >= 384 and method != "bogus"), "reference refused", argv, err)


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(**COMPARE_DRAW)
@counted(OUTCOMES)
def test_compare(tmp_path, **draw):
    compare_case(tmp_path, **draw)


@pytest.mark.slow
@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(**COMPARE_DRAW)
@counted(OUTCOMES)
def test_compare_many(tmp_path, **draw):
    compare_case(tmp_path, **draw)


IDENTIFY_DRAW = dict(
    mode=st.sampled_from(["displacement", "force"]), record_mode=st.sampled_from(["displacement", "force"]),
    n=st.sampled_from([N, 384, 3, 20, 383]), rate=st.sampled_from([1.0, 1.0, 1.0, 1e-6, 1e3]),
    noise=st.sampled_from([0.0, 0.0, 0.01]), defect=st.sampled_from(DEFECTS),
    column=st.sampled_from(("time",) + COLUMNS), at=st.floats(0, 1),
    rig_change=st.sampled_from(["none"] * 8 + ["value", "value", "unknown", "missing", "empty", "generic"]),
    key=st.sampled_from(RIG_KEYS), value=st.sampled_from(RIG_VALUES),
    dt=st.sampled_from(["none"] * 10 + ["record", "half", "double"] + FLOAT_FLAGS),
    fit=st.sampled_from([None] * 4 + ["K_v", "K_v,k", "k,c", "nope", "K_v,K_v", ",", "G_p,C_l"]),
    specimen=st.sampled_from(["linear"] * 5 + ["bouc_wen", "mr_damper", "bogus"]),
    max_nfev=st.sampled_from(["2"] * 6 + ["0", "-1", "x"]), second=st.booleans())
#: the default run's draws: one fitted key or a few, short records at a fast rate (an accepted one
#: in seconds); the whole default key set, 1,000 samples and 2 s samples in the slow run
IDENTIFY_DRAW_FAST = {**IDENTIFY_DRAW, "n": st.sampled_from([384, 3, 20, 383]), "rate": st.sampled_from([1.0, 1e-6]),
                      "fit": st.sampled_from(["K_v"] * 4 + ["K_v,k", "k,c", "nope", "K_v,K_v", ",", "G_p,C_l"])}


def identify_case(tmp_path, mode, record_mode, n, rate, noise, defect, column, at, rig_change, key, value, dt,
                  fit, specimen, max_nfev, second):
    """One drawn identify: a named error, or the whole output set, an uncertainty that holds
    its invariants, an end no worse than the start, and the reference rig kept at ~0 NRMSE."""
    rec, rig, out = _paths(tmp_path, record_mode, n, defect, column, rig_change, key, value)
    if (rig_change == "generic" or rate > 1.0) and n > 384:
        # the generic start costs tens of seconds on long records, and 1,000 samples of 2 s are
        # 2,000 s of plant time per evaluation (two such records: about 70 s, all of it work)
        n = 384
    exact = write_record(rec, record_mode, n, rate, noise, defect, column, at)
    exact &= rig_change != "generic" and write_rig(rig, rig_change, key, value) and record_mode == mode
    exact &= dt in ("none", "record") and specimen == "linear"
    argv = ["identify", str(rec)] + ([str(rec)] if second else []) + ["--mode", mode, "--out", str(out), "--quiet",
                                                                      f"--max-nfev={max_nfev}",
                                                                      "--specimen", specimen]
    argv += ["--rig", str(rig)] if rig_change != "generic" else []
    argv += [f"--dt={_dt_flag(dt)}"] if _dt_flag(dt) is not None else []
    argv += [f"--fit={fit}"] if fit is not None else []
    outcome, code, err = _run(argv)
    _check_outcome(argv, outcome, code, err, out, IDENTIFY_FILES)
    if outcome != "ok":
        return
    data = json.loads((out / "identification.json").read_text())
    corr = np.array(data["correlation"]["matrix"], dtype=float)
    _require(np.allclose(corr, corr.T, equal_nan=True), "asymmetric correlation", argv, corr)
    _require(np.all(np.abs(corr[np.isfinite(corr)]) <= 1.0 + 1e-9), "correlation beyond 1", argv, corr)
    costs = data["costs"]
    _require(costs[data["kept"]] <= costs["start"] * (1 + 1e-9) + 1e-12, "worse than its start", argv, costs)
    sh.load_rig(out / "rig_identified.toml")
    OUTCOMES["identify: ok"] += 1
    if exact and n >= 384 and fit in (None, "K_v", "K_v,k", "k,c"):
        OUTCOMES["identify: reference checked"] += 1
        for r in data["records"]:
            for ch, v in r["after"].items():
                _require(v < 1.0, "wrong answer", argv, f"{ch} NRMSE {v} % after identifying from its own record")


@settings(max_examples=15, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(**IDENTIFY_DRAW_FAST)
@example(mode="force", record_mode="force", n=384, rate=1.0, noise=0.0, defect="none", column="time", at=0.5,
         rig_change="none", key="m", value="2", dt="none", fit="K_v", specimen="linear", max_nfev="2", second=False)
@example(mode="force", record_mode="force", n=384, rate=1.0, noise=0.01, defect="none", column="time", at=0.5,
         rig_change="value", key="K_v", value="2", dt="record", fit="K_v,k", specimen="linear", max_nfev="2",
         second=True)
@counted(OUTCOMES)
def test_identify(tmp_path, **draw):
    identify_case(tmp_path, **draw)


@pytest.mark.slow
@settings(max_examples=200, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(**IDENTIFY_DRAW)
@counted(OUTCOMES)
def test_identify_many(tmp_path, **draw):
    identify_case(tmp_path, **draw)


# ----------------------------------------------------------------------------- the real process

@pytest.mark.parametrize("command, defect, dt, expected", [
    ("compare", "none", None, 0),
    ("compare", "nan", None, 2),
    ("identify", "none", "0", 2),
    ("identify", "duplicate_time", None, 2),
])
def test_subprocess_smoke(tmp_path, command, defect, dt, expected):
    """The command in its own interpreter: the exit code, one line, no traceback, bounded time."""
    rec, rig = tmp_path / "rec.csv", tmp_path / "rig.toml"
    write_record(rec, "displacement", N, 1.0, 0.0, defect, "displacement", 0.5)
    write_rig(rig, "none", "m", "1")
    argv = [sys.executable, "-m", "servohydraulics", command, str(rec), "--rig", str(rig), "--mode", "displacement",
            "--out", str(tmp_path / "out")]
    argv += ["--quiet", "--max-nfev=2", "--fit=K_v"] if command == "identify" else []
    argv += [f"--dt={dt}"] if dt else []
    p = subprocess.run(argv, capture_output=True, text=True, timeout=BOUND_S)
    assert p.returncode == expected, p.stderr
    assert "Traceback" not in p.stderr and "internal error" not in p.stderr
    if expected:
        assert len(p.stderr.strip().splitlines()) == 1 and NAMED.search(p.stderr), p.stderr


# ----------------------------------------------------------------------------- record files and their flags

#: file unit -> factor from SI, per kind
LENGTHS = {"m": 1.0, "mm": 1e3, "in": 1 / 0.0254}
FORCES = {"N": 1.0, "kN": 1e-3}
FORMATS = ["csv", "csv", "semicolon_comma", "tab", "whitespace", "mat_vectors", "mat_struct", "daq"]
FILE_DEFECTS = ["none"] * 8 + ["truncated", "count_lie", "mixed_delimiters", "missing_variable"]


def write_file(path: Path, mode: str, fmt: str, length: str, force: str, named_units: bool, defect: str
               ) -> tuple[Path, dict, dict]:
    """The reference record written in a drawn format and units; returns (path, the flags that
    read it right, the columns the file uses)."""
    ref = reference(mode)
    cmd_kind = LENGTHS if mode == "displacement" else FORCES
    cmd_unit = length if mode == "displacement" else force
    f = {"time": 1.0, "command": cmd_kind[cmd_unit], "displacement": LENGTHS[length], "force": FORCES[force]}
    unit = {"time": "s", "command": cmd_unit, "displacement": length, "force": force}
    cols = {k: ref[k] * f[k] for k in ("time", "command", "displacement", "force")}
    names = {k: (f"{k}_{unit[k]}" if named_units else k) for k in cols}
    right = {} if named_units else {"units": ",".join(f"{k}={unit[k]}" for k in cols if unit[k] not in ("m", "N", "s"))}
    if fmt.startswith("mat"):
        from scipy.io import savemat

        path = path.with_suffix(".mat")
        data = {names[k]: v for k, v in cols.items()}
        if defect == "missing_variable":
            data.pop(names["force"])
        savemat(path, {"rec": data} if fmt == "mat_struct" else data)
        return path, right, names
    if fmt == "daq":  # a header block, sample numbers, channels in volts (scale 0.01 unit/V)
        lines = ["Header Size:  7", "Version:  2", f"Sampling Interval:  {DT}", f"Sampling Rate:  {1 / DT:g}",
                 f"Sample Count:  {N + (5 if defect == 'count_lie' else 0)}", "Device Serial Number:  0",
                 "Sample Number, CHANNEL0, CHANNEL1, CHANNEL2, Events"]
        for k in range(N):
            lines.append(f"{k + 1:>8}, {cols['displacement'][k] / 0.01:.9g}, {cols['force'][k] / 0.01:.9g}, "
                         f"{cols['command'][k] / 0.01:.9g}" + (", DAQ Start" if k == 0 else ""))
        text = "\n".join(lines) + "\n"
        if defect == "truncated":
            text = text[: len(text) - 15]
        path.write_text(text)
        lay = path.with_name(path.stem + "_layout.toml")
        lay.write_text('sample_interval = "Sampling Interval"\n[columns]\ntime = "Sample Number"\n'
                       'command = "CHANNEL2"\ndisplacement = "CHANNEL0"\nforce = "CHANNEL1"\n'
                       f'[units]\ntime = "samples"\ncommand = "{unit["command"]}"\ndisplacement = "{length}"\n'
                       f'force = "{force}"\n[scale]\ncommand = 0.01\ndisplacement = 0.01\nforce = 0.01\n')
        return path, {"layout": str(lay)}, names
    sep, dec = {"csv": (",", "."), "semicolon_comma": (";", ","), "tab": ("\t", "."), "whitespace": ("  ", ".")}[fmt]
    rows = []
    for k in range(N):
        cells = [repr(float(cols[c][k])) for c in cols]
        if dec == ",":
            cells = [c.replace(".", ",") for c in cells]
        rows.append(sep.join(cells))
    if defect == "mixed_delimiters":
        rows[N // 2] = rows[N // 2].replace(sep, "|")
    if defect == "truncated":
        rows[-1] = rows[-1][: len(rows[-1]) // 2].rstrip(sep)
    path.write_text(sep.join(names[c] for c in cols) + "\n" + "\n".join(rows) + "\n")
    return path, right, names


READ_DRAW = dict(
    mode=st.sampled_from(["displacement", "force"]), fmt=st.sampled_from(FORMATS),
    length=st.sampled_from(["m", "m", "mm", "in"]), force=st.sampled_from(["N", "N", "kN"]),
    named_units=st.booleans(), defect=st.sampled_from(FILE_DEFECTS),
    flags=st.sampled_from(["right"] * 6 + ["none", "none", "bad_unit", "wrong_dimension", "malformed",
                                           "scale_zero", "scale_text", "column_missing", "column_unknown",
                                           "accept_warning", "accept_error", "accept_bogus"]))


def read_case(tmp_path, mode, fmt, length, force, named_units, defect, flags):
    """One drawn record file and flags through ``compare``: a named error with nothing written,
    or the whole output set; the right reading compares at ~0 NRMSE, and a wrong one (no
    units given for a file in mm, in or kN) is never silent: refused, or a warning on screen."""
    tag = uuid.uuid4().hex[:8]
    rec, right, names = write_file(tmp_path / f"rec_{fmt}_{length}_{force}_{defect}_{tag}.txt", mode, fmt, length,
                                   force, named_units, defect)
    rig, out = tmp_path / f"rig_{tag}.toml", tmp_path / f"out_{tag}"
    write_rig(rig, "none", "m", "1")
    argv = ["compare", str(rec), "--rig", str(rig), "--mode", mode, "--out", str(out)]
    correct = flags in ("right", "accept_warning") and defect == "none"
    if flags in ("right", "accept_warning"):
        argv += [f"--{k}={v}" for k, v in right.items() if v]
    elif flags == "bad_unit":
        argv += ["--units", "displacement=mmm"]
    elif flags == "wrong_dimension":
        argv += ["--units", "force=mm"]
    elif flags == "malformed":
        argv += ["--units", "displacement"]
    elif flags == "scale_zero":
        argv += ["--scale", "force=0"]
    elif flags == "scale_text":
        argv += ["--scale", "force=big"]
    elif flags == "column_missing":
        argv += ["--columns", "force=no_such_column"]
    elif flags == "column_unknown":
        argv += ["--columns", "forse=force"]
    elif flags.startswith("accept_"):
        argv += ["--accept", {"accept_error": "displacement_outside_stroke", "accept_bogus": "bogus"}[flags]]
    if flags == "accept_warning":
        argv += ["--accept", "flat_at_limit,run_spool"]
    outcome, code, err = _run(argv)
    _check_outcome(argv, outcome, code, err, out, COMPARE_FILES)
    truly_si = (length == "m" and force == "N") or named_units or flags in ("right", "accept_warning")
    if outcome == "ok":
        data = json.loads((out / "comparison.json").read_text())
        worst = max(m["nrmse_pct"] for m in data["channels"].values())
        if correct and (truly_si or fmt == "daq"):
            OUTCOMES["read: right reading checked"] += 1
            _require(worst < 1.0, "wrong answer", argv, f"NRMSE {worst} % on the rig's own record")
        elif worst > 5.0:  # a misreading that ran: it must have said so
            OUTCOMES["read: misread, warned"] += 1
            _require("warning:" in err, "silent misreading", argv, f"NRMSE {worst} %, no warning")
    else:
        _require(not (correct and (truly_si or fmt == "daq")), "right reading refused", argv, err)


@settings(max_examples=8, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(**READ_DRAW)
@example(mode="displacement", fmt="csv", length="mm", force="N", named_units=False, defect="none", flags="none")
@example(mode="displacement", fmt="daq", length="mm", force="kN", named_units=False, defect="none", flags="right")
@example(mode="force", fmt="mat_struct", length="m", force="kN", named_units=True, defect="none", flags="right")
@counted(OUTCOMES)
def test_record_files_and_flags(tmp_path, **draw):
    read_case(tmp_path, **draw)


@pytest.mark.slow
@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(**READ_DRAW)
@counted(OUTCOMES)
def test_record_files_and_flags_many(tmp_path, **draw):
    read_case(tmp_path, **draw)
