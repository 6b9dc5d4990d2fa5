"""Round trips: rig TOML files (save_rig/load_rig) and record CSV files, and
the flow curve's inverse, with hypothesis property tests."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import servohydraulics as sh
from servohydraulics.records import read_record, write_record
from servohydraulics.rig import CHOICES, EFFECTS, PARAMETERS

# ---- rig files ----------------------------------------------------------------


def _assert_same_rig(a: sh.Rig, b: sh.Rig) -> None:
    for p in PARAMETERS:
        assert getattr(a, p.key) == getattr(b, p.key), p.key  # bit-exact: TOML keeps repr(float)
    for name in EFFECTS:
        assert getattr(a.effects, name) == getattr(b.effects, name), name
    fa, fb = a.flow_curve, b.flow_curve
    assert fa.kind == fb.kind
    if fa.kind == sh.FlowCurve.Kind.Rational:
        assert fa.b == fb.b
    else:
        assert list(fa.opening) == list(fb.opening) and list(fa.flow) == list(fb.flow)
    assert sh.rig_to_dict(a) == sh.rig_to_dict(b)


def _every_field_changed() -> sh.Rig:
    """A rig in which every parameter and switch differs from the preset, so a
    field that save/load dropped would fall back to the preset and show."""
    rig = sh.zhao2003()
    for i, p in enumerate(PARAMETERS):
        if _BOUNDS[p.key] == "an integer in 1..6":  # the Pade order: another integer
            setattr(rig, p.key, getattr(rig, p.key) % 6 + 1)
            continue
        zero_default = getattr(sh.zhao2003(), p.key) == 0.0
        offset = 0.125 * 1e-3 if zero_default else 0.0  # defaults of 0 must change too (delays: < 64 samples)
        setattr(rig, p.key, getattr(rig, p.key) * (1.0 + 0.01 * (i + 1)) + offset)
    for name in EFFECTS:
        setattr(rig.effects, name, not getattr(rig.effects, name))
    curve = sh.FlowCurve()
    curve.kind = sh.FlowCurve.Kind.Table
    curve.opening = [0.0, 0.1, 0.5, 1.0]
    curve.flow = [0.0, 0.1, 0.4, 0.6]
    rig.flow_curve = curve
    # the choices off their defaults; the MR damper reads one field input, the other must be 0
    rig.mr_input, rig.mr_law = sh._core.MrInput.Current, sh._core.MrLaw.Quiroz2022
    rig.mr_voltage = 0.0
    return rig


def test_every_parameter_is_in_the_rig_file():
    """PARAMETERS (the file's keys) covers every numeric field of the C++ Rig."""
    fields = {n for n in dir(sh.Rig()) if not n.startswith("_")} - {"effects", "flow_curve", "validate"}
    assert fields == {p.key for p in PARAMETERS} | set(CHOICES)


@pytest.mark.parametrize("which", ["calibrated", "printed", "every-field-changed"])
def test_rig_toml_round_trip(tmp_path, which):
    rig = _every_field_changed() if which == "every-field-changed" else sh.zhao2003(which)
    path = sh.save_rig(rig, tmp_path / "rig.toml")
    back = sh.load_rig(path)
    _assert_same_rig(rig, back)
    if which == "every-field-changed":
        for p in PARAMETERS:  # (mr_voltage: 0 as the preset's, the rig reads mr_current)
            assert p.key == "mr_voltage" or getattr(back, p.key) != getattr(sh.zhao2003(), p.key), p.key
        for key in CHOICES:
            assert getattr(back, key) != getattr(sh.zhao2003(), key), key
    # Saving what was loaded writes the same file.
    again = sh.save_rig(back, tmp_path / "again.toml")
    assert again.read_text() == path.read_text()


def test_partial_rig_file_keeps_the_preset(tmp_path):
    path = tmp_path / "rig.toml"
    path.write_text("[structure]\nm = 3000.0\n[effects]\ncoulomb_friction = false\n")
    rig = sh.load_rig(path)
    preset = sh.zhao2003()
    assert rig.m == 3000.0 and not rig.effects.coulomb_friction
    assert rig.k == preset.k and rig.K_a == preset.K_a and rig.effects.load_pressure


_positive = st.floats(min_value=1e-9, max_value=1e9, allow_nan=False, allow_infinity=False)
_nonneg = st.one_of(st.just(0.0), _positive)
# The bound of every key, from the core's table (parameters.hpp: kRigParameters).
_BOUNDS = {p["key"]: p["bound"] for p in sh._core.RIG_PARAMETERS}
_NONNEG_KEYS = {k for k, b in _BOUNDS.items() if b == "finite and >= 0"}
_AT_LEAST_ONE_KEYS = {k for k, b in _BOUNDS.items() if b == "finite and >= 1"}  # F_s / F_c, Bouc-Wen n
_INTEGER_KEYS = {k for k, b in _BOUNDS.items() if b == "an integer in 1..6"}  # the Pade order


@st.composite
def _flow_curves(draw) -> sh.FlowCurve:
    curve = sh.FlowCurve()
    if draw(st.booleans()):
        curve.kind = sh.FlowCurve.Kind.Rational
        curve.b = draw(st.floats(min_value=0.0, max_value=10.0))
    else:
        n = draw(st.integers(min_value=2, max_value=8))
        steps_x = draw(st.lists(st.floats(min_value=1e-3, max_value=1.0), min_size=n - 1, max_size=n - 1))
        steps_q = draw(st.lists(st.floats(min_value=1e-3, max_value=1.0), min_size=n - 1, max_size=n - 1))
        curve.kind = sh.FlowCurve.Kind.Table
        curve.opening = [0.0, *np.cumsum(steps_x).tolist()]
        curve.flow = [0.0, *np.cumsum(steps_q).tolist()]
    return curve


_FINITE_KEYS = {k for k, b in _BOUNDS.items() if b == "finite"}  # signed: the thesis' MR-damper law terms


@st.composite
def _rigs(draw) -> sh.Rig:
    rig = sh.Rig()
    for p in PARAMETERS:
        if p.key in _INTEGER_KEYS:
            setattr(rig, p.key, float(draw(st.integers(min_value=1, max_value=6))))
        elif p.key in _AT_LEAST_ONE_KEYS:
            setattr(rig, p.key, 1.0 + draw(_nonneg))
        elif p.key in _FINITE_KEYS:
            setattr(rig, p.key, draw(st.floats(min_value=-1e3, max_value=1e3)))
        else:
            setattr(rig, p.key, draw(_nonneg if p.key in _NONNEG_KEYS else _positive))
    for name in EFFECTS:
        setattr(rig.effects, name, draw(st.booleans()))
    rig.flow_curve = draw(_flow_curves())
    # the MR damper's choices, and what they require of its keys (elements/mr_damper.hpp: validate_mr_law)
    for key, (_, names) in CHOICES.items():
        setattr(rig, key, names[draw(st.sampled_from(sorted(names)))])
    setattr(rig, "mr_voltage" if rig.mr_input == sh._core.MrInput.Current else "mr_current", 0.0)
    if rig.mr_law == sh._core.MrLaw.Spencer:
        rig.mr_alpha_c = rig.mr_bw_decay = 0.0
    else:  # alpha(u) >= 0 and beta, gamma finite at the run's u
        u = max(rig.mr_voltage, rig.mr_current)
        # (1 - 1e-9): alpha(u) just above 0, not on it, where rounding could give -2e-16
        rig.mr_alpha_c = max(rig.mr_alpha_c, -(1.0 - 1e-9) * (rig.mr_alpha_a + rig.mr_alpha_b * u) / max(u * u, 1e-300))
        rig.mr_bw_decay = max(rig.mr_bw_decay, -1.0 / max(u, 1e-300))
    rig.mr_law_min, rig.mr_law_max = sorted((rig.mr_law_min, rig.mr_law_max))
    rig.validate()
    return rig


@settings(max_examples=60, deadline=None)
@given(_rigs())
def test_rig_round_trip_random_valid_rigs(rig):
    with tempfile.TemporaryDirectory() as d:
        back = sh.load_rig(sh.save_rig(rig, Path(d) / "rig.toml"))
    _assert_same_rig(rig, back)


# ---- flow curve ---------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(curve=_flow_curves(), frac=st.floats(min_value=-1.0, max_value=1.0))
def test_flow_curve_inverse_of_eval(curve, frac):
    """inverse(eval(x)) == x over the curve's range (relative 1e-12 of the range:
    a handful of roundings), eval is odd and increasing, eval(0) = 0."""
    curve.validate()
    top = 1.0 if curve.kind == sh.FlowCurve.Kind.Rational else curve.opening[-1]
    x = frac * top
    q = curve.eval(x)
    assert curve.inverse(q) == pytest.approx(x, abs=1e-12 * top)
    assert curve.eval(-x) == -q
    assert curve.eval(0.0) == 0.0
    if x > 1e-9 * top:
        assert q > 0 and curve.eval(x * (1 - 1e-6)) < q


def test_rational_flow_curve_shape():
    """g(x) = x / (1 + b|x|): unit slope at the null, g(1) = 1/(1+b), slope at
    full opening 1/(1+b)^2 (the gain falls with opening, Fig 4a)."""
    curve = sh.FlowCurve()
    b = curve.b
    assert curve.slope(0.0) == 1.0
    assert curve.eval(1.0) == pytest.approx(1 / (1 + b), rel=1e-15)
    assert curve.slope(1.0) == pytest.approx(1 / (1 + b) ** 2, rel=1e-15)
    h = 1e-6
    assert (curve.eval(0.5 + h) - curve.eval(0.5 - h)) / (2 * h) == pytest.approx(curve.slope(0.5), rel=1e-8)


# ---- record files ---------------------------------------------------------------


def test_record_csv_round_trip(calibrated, tmp_path, dt):
    """A simulated record written and read back: every channel to the 10
    significant digits of the file format (relative 5e-10), and writing what
    was read gives the same file."""
    t = np.arange(401) * dt
    res = sh.simulate(calibrated, mode="displacement", command=2e-3 * np.sin(2 * np.pi * 2 * t), dt=dt)
    path = write_record(tmp_path / "run.csv", res)
    header = path.read_text().splitlines()[0].split(",")
    assert header[:4] == ["time", "command", "displacement", "force"]
    rec = read_record(path)
    assert len(rec) == len(res.time)
    assert rec.dt == pytest.approx(dt, rel=1e-9)
    for name in header:
        original = np.asarray(getattr(res, name), dtype=float)
        scale = np.max(np.abs(original))
        np.testing.assert_allclose(rec.channels[name], original, rtol=5e-10, atol=1e-300 + 5e-10 * scale * 1e-6)
    again = write_record(tmp_path / "again.csv", rec)
    assert again.read_text() == path.read_text()
    assert not math.isnan(rec.force.sum())
