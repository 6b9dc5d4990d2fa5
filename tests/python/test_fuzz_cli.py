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
