"""The command line under bad invocations (docs/robustness.md): the hand-made
cases of cli_cases.py and hypothesis-drawn ``simulate`` arguments.  Every
invocation ends with exit 0 and a complete file, or a non-zero exit and one
error line that names the field, value or file, with no output file and no
temporary left behind; never a traceback."""

from __future__ import annotations

import atexit
import math
import shutil
import tempfile
import uuid
from pathlib import Path

import pytest
from cli_cases import make_cases, run_case
from fuzz_support import Tally, counted
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from servohydraulics.records import read_record

_CASE_DIR = Path(tempfile.mkdtemp(prefix="sh_cli_cases_"))
atexit.register(shutil.rmtree, _CASE_DIR, True)
CASES = make_cases(_CASE_DIR)
OUTCOMES = Tally()


def teardown_module() -> None:
    OUTCOMES.report(__name__)


@pytest.mark.parametrize("name, argv, expected", CASES, ids=[c[0] for c in CASES])
def test_bad_invocation_is_one_named_error_line(name, argv, expected):
    outcome, code, err = run_case(argv)
    assert outcome == "error", f"{name}: {outcome}: {err}"
    assert code in (1, 2)
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert "Traceback" not in err
    assert expected in err, f"{name}: the message does not name {expected!r}: {err}"
    if code == 1:
        assert len(lines) == 1 and "internal error" not in err, err
    out = argv[argv.index("--out") + 1] if "--out" in argv else None
    if out and name.startswith("simulate") and Path(out).name:
        assert not Path(out).is_file(), f"{name}: left an output file"
        assert not list(Path(out).parent.glob(f".{Path(out).name}.*.tmp*")) if Path(out).parent.is_dir() else True


def _value(v: float) -> str:
    return repr(v)


FLOATS = st.one_of(st.sampled_from([0.0, -1.0, math.nan, math.inf, -math.inf, 1e300, 1e-300]),
                   st.floats(-1e3, 1e3))


@settings(max_examples=400, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(mode=st.sampled_from(["displacement", "force", "free", "bogus"]),
       dt=st.one_of(st.sampled_from([5e-4, 1e-3]), FLOATS), duration=st.one_of(st.floats(0.001, 0.05), FLOATS),
       amplitude=st.one_of(st.floats(-0.01, 0.01), FLOATS), frequency=st.one_of(st.floats(0.1, 50), FLOATS),
       x0=st.one_of(st.floats(-0.01, 0.01), FLOATS))
@counted(OUTCOMES)
def test_simulate_arguments(tmp_path, mode, dt, duration, amplitude, frequency, x0):
    # Keep the valid runs short (the bound on the work of one invocation: 2000 samples).
    if math.isfinite(dt) and math.isfinite(duration) and dt > 0 and duration > 0 and 2000 < duration / dt < 1e7:
        duration = 2000 * dt
    out = tmp_path / f"{uuid.uuid4().hex[:8]}.csv"
    argv = ["simulate", "--mode", mode, "--dt", _value(dt), "--duration", _value(duration),
            "--amplitude", _value(amplitude), "--frequency", _value(frequency), "--x0", _value(x0), "--out", str(out)]
    outcome, code, err = run_case(argv)
    OUTCOMES[outcome] += 1
    assert outcome in ("ok", "error"), f"{argv}: {err}"
    assert "Traceback" not in err and "internal error" not in err, err
    leftovers = [p for p in tmp_path.iterdir() if p.name.startswith(f".{out.name}.")]
    assert not leftovers, leftovers
    if outcome == "ok":
        rec = read_record(out)  # complete and readable
        assert len(rec) == round(duration / dt) + 1
    else:
        assert not out.exists(), "a failed invocation left its output file"
        assert err.strip().startswith(("servohydraulics simulate: error:", "usage:")), err


# ----------------------------------------------------------------------------- fmu export flags (issue 26)

NAMES = st.one_of(st.sampled_from(["plant_1", "a" * 200, "a" * 201, "a" * 5000, "x<y", "a&b", "\x01", "é", "1abc",
                                   "", "class"]), st.text(max_size=30))
SETTINGS = st.lists(st.tuples(st.sampled_from(["compensation", "lead_T", "alpha", "mass", "compute_delay", "m_m",
                                               "scheme", "delay_T", "physical_mass_fraction", "solver_options",
                                               "name", "foo", ""]),
                              st.one_of(st.sampled_from(["nonlinear", "1", "nan", "-1", "1e300", "1j", "", "="]),
                                        st.floats(allow_nan=True).map(repr))), max_size=2)


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(kind=st.sampled_from(["plant", "eft", "rpsd", "valve"]),
       mode=st.sampled_from([None, "displacement", "force", "free"]),
       dt=st.one_of(st.none(), st.sampled_from([5e-4, 1e-3, 1e-7, 5e-16]), FLOATS),
       x0=st.one_of(st.floats(-0.01, 0.01), FLOATS), name=st.one_of(st.none(), NAMES), sets=SETTINGS)
@counted(OUTCOMES)
def test_fmu_export_flags(tmp_path, kind, mode, dt, x0, name, sets):
    """Every drawn export ends in a valid FMU (its XML parses, its stepSize is the finite dt, the
    file follows the umask) or one named error and no file."""
    import os
    import stat
    from xml.etree import ElementTree as ET
    from zipfile import ZipFile

    out = tmp_path / f"{uuid.uuid4().hex[:8]}.fmu"
    argv = ["fmu", "--kind", kind, f"--x0={x0!r}", "--out", str(out)]
    argv += ["--mode", mode] if mode else []
    argv += [f"--dt={dt!r}"] if dt is not None else []
    argv += [f"--name={name}"] if name is not None else []
    for key, value in sets:
        argv += ["--set", f"{key}={value}"]
    outcome, code, err = run_case(argv)
    OUTCOMES[outcome] += 1
    assert outcome in ("ok", "error"), f"{argv}: {err}"
    assert "Traceback" not in err and "internal error" not in err, err
    if outcome == "error":
        assert code == 2 and "error: " in err, err
        assert not out.exists(), f"{argv}: left a file"
    else:
        with ZipFile(out) as z:
            md = ET.fromstring(z.read("modelDescription.xml"))
        step = float(md.find("DefaultExperiment").get("stepSize"))
        assert math.isfinite(step) and step >= 1e-7 and (dt is None or step == dt)
        assert stat.S_IMODE(os.stat(out).st_mode) == 0o666 & ~_umask()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "temporary left behind"


def _umask() -> int:
    import os

    mask = os.umask(0)
    os.umask(mask)
    return mask


# ----------------------------------------------------------------------------- rths data folders (issue 26)

@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(matrix=st.sampled_from(["M", "C", "K"]),
       change=st.sampled_from(["none", "negate", "zero", "asymmetric", "nan", "inf", "complex", "row", "transpose",
                               "scale", "missing", "text", "empty"]),
       record=st.sampled_from(["none", "shuffle", "repeat", "uneven", "nan", "one_row", "three_rows", "reverse",
                               "missing", "empty_file", "garbage_file"]),
       scale=st.floats(1e-6, 1e6))
@counted(OUTCOMES)
def test_rths_data_folder(tmp_path, matrix, change, record, scale):
    """A drawn official-layout folder (Case_1.mat, ElCentroAccelNoScaling.mat) with one defect: the
    loaders return data that hold the benchmark's invariants, or a ValueError naming the file."""
    import numpy as np
    import scipy.io as sio

    from servohydraulics.rths.data import embedded_case, load_case, load_record

    c = embedded_case(1)
    mats = {"M": c.M.copy(), "C": c.C.copy(), "K": c.K.copy()}
    a = mats[matrix]
    mats[matrix] = {"none": a, "negate": -a, "zero": 0 * a, "nan": np.where(a == a.max(), np.nan, a),
                    "inf": np.where(a == a.max(), np.inf, a), "complex": a * (1 + 1e-3j), "row": a[:2],
                    "transpose": a.T, "scale": a * scale, "text": "abc", "empty": np.zeros((0, 0)),
                    "asymmetric": a + np.triu(np.full(a.shape, 1e-3 * np.abs(a).max()), 1), "missing": None}[change]
    sio.savemat(tmp_path / "Case_1.mat", {k: v for k, v in mats.items() if v is not None})
    t = np.arange(300) * 0.01
    acc = np.sin(3 * t)
    rows = {"none": [t, acc], "shuffle": [np.r_[t[:5], t[6], t[5], t[7:]], acc], "repeat": [np.r_[t[:5], t[4:-1]], acc],
            "uneven": [t + np.where(t > 1, 0.004, 0), acc], "nan": [t, np.where(t > 2, np.nan, acc)],
            "one_row": [t], "three_rows": [t, acc, acc], "reverse": [t[::-1], acc]}.get(record)
    path = tmp_path / "ElCentroAccelNoScaling.mat"
    if rows is not None:
        sio.savemat(path, {"ElCentroAccel": np.vstack(rows)})
    elif record == "missing":
        sio.savemat(path, {"Other": t})
    else:
        path.write_bytes(b"" if record == "empty_file" else b"MATLAB 5.0 MAT-file\0" + bytes(range(256)))
    for load, file in ((lambda: load_case(tmp_path, 1), "Case_1.mat"),
                       (lambda: load_record(tmp_path, "elcentro"), "ElCentroAccelNoScaling.mat")):
        try:
            got = load()
        except ValueError as e:
            OUTCOMES["error"] += 1
            assert str(tmp_path / file) in str(e), f"the message does not name the file: {e}"
            continue
        OUTCOMES["ok"] += 1
        if file == "Case_1.mat":  # a silent wrong answer would break one of these
            for m in (got.M, got.C, got.K):
                assert m.dtype == float and m.shape == (3, 3) and np.all(np.isfinite(m)) and np.allclose(m, m.T)
            assert np.linalg.eigvalsh(got.M).min() > 0 and np.linalg.eigvalsh(got.K).min() > 0
        else:
            assert np.all(np.isfinite(got.acceleration)) and np.all(np.diff(got.time) > 0)
            assert np.allclose(np.diff(got.time), 0.01)
