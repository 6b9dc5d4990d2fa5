"""Property tests of the file readers with hypothesis (docs/robustness.md): rig
TOML text and record CSV text, drawn from valid files, hostile values and
random mutations.  A reader returns a valid object or raises ValueError (or
FileNotFoundError) whose message names the file; it never raises another
type.  A record read is finite, uniformly sampled and survives a round trip
through ``to_csv``."""

from __future__ import annotations

import math
import string
import uuid

import numpy as np
from fuzz_support import Tally, counted
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import servohydraulics as sh
from servohydraulics.records import read_record, write_record
from servohydraulics.response import channel_units

FUZZ = settings(max_examples=1000, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
OUTCOMES = Tally()


def teardown_module() -> None:
    OUTCOMES.report(__name__)


def _fresh(tmp_path, name: str):
    return tmp_path / f"{uuid.uuid4().hex[:8]}_{name}"


# ---- TOML -------------------------------------------------------------------------------------------
SECTIONS = sorted({p.section for p in sh.PARAMETERS}) + ["effects", "bogus"]
KEYS = [p.key for p in sh.PARAMETERS] + list(sh.rig.EFFECTS) + ["flow_curve", "mass", ""]
TOML_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**400), 10**400).map(str),
    st.sampled_from(["true", "false", '"text"', "[]", "[0.0, 0.5, 1.0]", "{}", "1e999", "-0.0", "0x10", "1_000"]),
)


@st.composite
def toml_texts(draw) -> str:
    lines = []
    for _ in range(draw(st.integers(0, 4))):
        lines.append(f"[{draw(st.sampled_from(SECTIONS))}]")
        for key in draw(st.lists(st.sampled_from(KEYS), max_size=4, unique=True)):
            if key:
                lines.append(f"{key} = {draw(TOML_VALUES)}")
    if draw(st.booleans()):
        kind = draw(st.sampled_from(["table", "rational", "spline"]))
        lines += ["[servovalve.flow_curve]", f'kind = "{kind}"']
        n = draw(st.integers(0, 4))
        lines.append("opening = [" + ", ".join(draw(TOML_VALUES) for _ in range(n)) + "]")
        lines.append("flow = [" + ", ".join(draw(TOML_VALUES) for _ in range(draw(st.integers(0, 4)))) + "]")
    text = "\n".join(lines) + "\n"
    if draw(st.booleans()):  # a random mutation: insert, delete or replace a few characters
        for _ in range(draw(st.integers(1, 3))):
            i = draw(st.integers(0, len(text)))
            text = text[:i] + draw(st.text(string.printable, max_size=3)) + text[i + draw(st.integers(0, 2)):]
    return text


@FUZZ
@given(text=toml_texts(), bom=st.booleans())
@counted(OUTCOMES)
def test_rig_files(tmp_path, text, bom):
    path = _fresh(tmp_path, "rig.toml")
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8", "surrogatepass"))
    try:
        rig = sh.load_rig(path)
    except ValueError as e:
        assert str(path) in str(e), f"the error does not name the file: {e}"
        OUTCOMES["toml: ValueError"] += 1
        return
    rig.validate()
    OUTCOMES["toml: valid rig"] += 1
    if bom:  # the byte-order mark is not part of the text: the same rig without it
        plain = _fresh(tmp_path, "plain.toml")
        plain.write_text(text, encoding="utf-8")
        assert sh.load_rig(plain) == rig
    # A rig that loads saves and loads back to the same rig.
    again = sh.load_rig(sh.save_rig(rig, _fresh(tmp_path, "again.toml")))
    assert again == rig


# ---- CSV --------------------------------------------------------------------------------------------
ALLOWED = list(channel_units("record"))
CELL = st.one_of(st.floats(-1e6, 1e6).map(lambda v: f"{v:.6g}"),
                 st.sampled_from(["nan", "inf", "", "x", "1e999", " 0"]))


@st.composite
def csv_texts(draw) -> str:
    names = ["time", "command", "displacement", "force"]
    names += draw(st.lists(st.sampled_from(ALLOWED + ["bogus", "force", "time"]), max_size=3))
    names = draw(st.permutations(names))
    if draw(st.booleans()):
        names = names[: draw(st.integers(0, len(names)))]
    n = draw(st.integers(0, 30))
    dt = draw(st.sampled_from([5e-4, 1e-3, 0.0, -5e-4]))
    jitter = draw(st.sampled_from([0.0, 0.0, 1e-5]))
    rows = []
    for k in range(n):
        cells = [f"{k * dt + (jitter if k == n // 2 else 0.0):.9g}" if c == "time" else
                 (draw(CELL) if draw(st.integers(0, 20)) == 0 else f"{0.001 * math.sin(k):.6g}") for c in names]
        if draw(st.integers(0, 40)) == 0:
            cells = cells[:-1]  # a ragged row
        rows.append(",".join(cells))
    bom = "\ufeff" if draw(st.booleans()) else ""
    return bom + ",".join(names) + "\n" + "\n".join(rows) + ("\n" if draw(st.booleans()) else "")


@FUZZ
@given(text=csv_texts())
@counted(OUTCOMES)
def test_record_files(tmp_path, text):
    path = _fresh(tmp_path, "record.csv")
    path.write_text(text, encoding="utf-8")
    try:
        rec = read_record(path)
    except ValueError as e:
        assert str(path) in str(e), f"the error does not name the file: {e}"
        OUTCOMES["csv: ValueError"] += 1
        return
    OUTCOMES["csv: record"] += 1
    header = [h.strip().lstrip("\ufeff") for h in text.split("\n", 1)[0].split(",")]
    assert len(set(header)) == len(header), "duplicate columns were accepted"
    assert len(rec) >= 2
    for name, v in rec.channels.items():
        assert np.all(np.isfinite(np.asarray(v, dtype=float))), name
    assert np.all(np.diff(rec.time) > 0)
    back = read_record(write_record(_fresh(tmp_path, "back.csv"), rec))
    assert list(back.channels) == list(dict.fromkeys(["time", "command", "displacement", "force", *rec.channels]))
    for name in rec.channels:
        np.testing.assert_allclose(back.channels[name], rec.channels[name], rtol=1e-9, atol=1e-12)


def test_bom_and_duplicate_columns(tmp_path):
    rows = "\n".join(f"{k * 5e-4:.6g},0,{k * 1e-5:.6g},1" for k in range(10))
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + ("time,command,displacement,force\n" + rows).encode())
    rec = read_record(bom)  # a spreadsheet's byte-order mark is not part of the name "time"
    assert rec.time[1] == 5e-4 and list(rec.channels)[0] == "time"
    dup = tmp_path / "dup.csv"
    dup.write_text("time,command,displacement,force,force\n" + "\n".join(f"{k * 5e-4:.6g},0,0,1,2" for k in range(5)))
    try:
        read_record(dup)
    except ValueError as e:
        assert "'force' appears twice" in str(e) and str(dup) in str(e)
    else:
        raise AssertionError("duplicate column names were accepted")
