"""The identification package as one piece: its covariance rule (against closed forms
and as a property), identification never ending worse than its start (issue 26,
defect 1), keys the records do not determine (defect 2), ``sh.identify`` and the
diagnosis giving the same interval for the same fit, the deprecated aliases, and
the import graph without cycles."""

from __future__ import annotations

import ast
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

import servohydraulics as sh
from servohydraulics.identification import stats
from servohydraulics.identification.coordinates import Coordinates

PACKAGE = Path(sh.__file__).parent


# --- the covariance rule ---------------------------------------------------------------------

def test_hac_variance_of_a_mean_of_ar1_noise_matches_the_long_run_variance():
    """Oracle: the mean of an AR(1) series e_t = phi e_t-1 + w_t has the asymptotic variance
    sigma_w^2 / (1 - phi)^2 / n; the sandwich (J = 1) recovers it within 15 %, while the
    white-noise rule s^2 / n is low by the factor (1 + phi) / (1 - phi) = 3."""
    n, phi = 40000, 0.5
    rng = np.random.default_rng(1)
    w = rng.standard_normal(n)
    e = signal.lfilter([1.0], [1.0, -phi], w)
    r = e - e.mean()
    cov = stats.covariance(np.ones((n, 1)), r)
    exact = 1.0 / (1 - phi) ** 2 / n
    assert cov.matrix[0, 0] == pytest.approx(exact, rel=0.15)
    assert float(r @ r) / n / n < 0.5 * exact


def test_white_residuals_give_the_classical_covariance():
    """For white residuals the sandwich is s^2 (J'J)^-1 (the Bartlett bandwidth is then 1-2 lags)."""
    rng = np.random.default_rng(2)
    J = rng.standard_normal((5000, 3)) * [1.0, 1e3, 1e-4]
    r = rng.standard_normal(5000) * 0.1
    classical = float(r @ r) / r.size * np.linalg.inv(J.T @ J)
    cov = stats.covariance(J, r, scale=[1.0, 1e-3, 1e4])
    np.testing.assert_allclose(np.diag(cov.matrix), np.diag(classical), rtol=0.1)


def test_an_undetermined_direction_gets_an_infinite_interval():
    """A zero column (a key the residual does not see: loop_delay with the effect off) and two
    identical columns (two keys that only act as their sum) are "not identified", with an
    infinite variance; a key independent of them keeps a finite one."""
    rng = np.random.default_rng(3)
    a, b = rng.standard_normal(2000), rng.standard_normal(2000)
    r = 0.01 * rng.standard_normal(2000)
    cov = stats.covariance(np.column_stack([a, np.zeros(2000), b, b]), r)
    assert list(cov.identified) == [True, False, False, False]
    assert np.isfinite(cov.sd[0]) and np.all(np.isinf(cov.sd[1:]))
    corr = cov.correlation
    assert corr[0, 0] == 1.0 and np.all(np.isnan(corr[1:, :]))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2 ** 31 - 1), p=st.integers(1, 6), rank=st.integers(0, 6),
       log_scale=st.floats(-8, 8), series=st.integers(1, 3))
def test_covariance_is_symmetric_with_correlations_in_the_unit_interval(seed, p, rank, log_scale, series):
    """Property: for any Jacobian (rank deficient, badly scaled, several series) the covariance is
    symmetric, its diagonal non-negative, its correlation symmetric with |corr| <= 1 and a unit
    diagonal wherever a key is identified (the old rule gave asymmetric matrices with entries
    up to 2.4)."""
    rng = np.random.default_rng(seed)
    n = 60 * series
    k = min(rank, p)
    J = (rng.standard_normal((n, k)) @ rng.standard_normal((k, p)) if k else np.zeros((n, p)))
    J = J * 10.0 ** (log_scale * rng.uniform(-1, 1, p))
    r = np.cumsum(rng.standard_normal(n)) * 1e-3
    cov = stats.covariance(J, r, lengths=[60] * series)
    m = cov.matrix
    assert np.array_equal(np.isinf(m), np.isinf(m.T))
    fin = np.isfinite(m) & np.isfinite(m.T)
    np.testing.assert_allclose(m[fin], m.T[fin], rtol=1e-12, atol=0.0)
    assert np.all(np.diag(m) >= 0)
    c = cov.correlation
    assert np.array_equal(np.isnan(c), np.isnan(c.T))
    ok = ~np.isnan(c)
    assert np.all(c[ok] == c.T[ok]) and np.all(np.abs(c[ok]) <= 1.0)
    assert cov.identified.sum() <= k
    assert np.all(np.diag(c)[cov.identified & (cov.sd > 0)] == 1.0)


def test_bad_input_names_the_field():
    with pytest.raises(ValueError, match="Jacobian shape"):
        stats.covariance(np.zeros((5, 2)), np.zeros(4))
    with pytest.raises(ValueError, match="lengths"):
        stats.covariance(np.ones((5, 1)), np.zeros(5), lengths=[2, 2])
    with pytest.raises(ValueError, match="level"):
        stats.quantile(1.5)
    with pytest.raises(ValueError, match="coordinate kinds"):
        Coordinates(("a",), np.zeros(1), ("cubic",), np.ones(1))


def test_coordinates_round_trip_every_kind():
    c = Coordinates(("a", "b", "f"), np.array([2.0, 3.0, 0.0]), ("log", "linear", "reciprocal"),
                    np.array([2.0, 3.0, 1.0]))
    v = np.array([5.0, -1.0, 40.0])
    np.testing.assert_allclose(c.values(c.z(v)), v, rtol=1e-14)
    assert c.values(np.array([0.0, 0.0, 0.0]))[2] == np.inf  # reciprocal 0: "absent", an infinite value
    assert c.interval(c.z(v)[2], np.inf, 2, 1.96) == (0.0, np.inf)  # an infinite sd: the whole range
    assert c.interval(c.z(v)[0], np.inf, 0, 1.96) == (0.0, np.inf)
    lo, hi = c.interval(1 / 40.0, 0.001, 2, 1.96)
    assert lo == pytest.approx(1 / (0.025 + 0.00196)) and hi == pytest.approx(1 / (0.025 - 0.00196))


# --- identification on simulated records ----------------------------------------------------

DT = 1e-3


def chirp_record(rig: sh.Rig, seed: int = 0, sigma_x: float = 2e-6, sigma_f: float = 20.0) -> sh.Response:
    """Issue 26's reproducer: a clean simulated 6 s chirp 0.5-20 Hz at 1 kHz (faded in and out over
    0.3 s), 2 mm, with 2 um / 20 N white noise."""
    t = np.arange(6001) * DT
    u = 2e-3 * signal.chirp(t, 0.5, t[-1], 20.0) * np.minimum(t / 0.3, 1.0) * np.minimum((t[-1] - t) / 0.3, 1.0)
    sim = sh.simulate(rig, "displacement", command=u, dt=DT)
    rng = np.random.default_rng(seed)
    return sh.Response({"time": t, "command": u,
                        "displacement": sim.displacement + sigma_x * rng.standard_normal(t.size),
                        "force": sim.force + sigma_f * rng.standard_normal(t.size)})


def test_identify_from_the_true_rig_never_ends_worse_than_it_starts():
    """Issue 26, defect 1: started at the true rig, the frequency stage moves far off (f_v 70.7 ->
    26 Hz) and the time stage from there failed; the result was 60 times worse than the start
    (displacement NRMSE 0.31 % -> 19.6 %).  Now the best of start and stages is kept by the
    time-domain cost: the result is not worse than the start on any channel."""
    rig = sh.zhao2003()
    rec = chirp_record(rig)
    ident = sh.identify([rec], rig=rig, mode="displacement", progress=False, max_nfev=20)
    assert ident.costs[ident.kept] <= ident.costs["start"]
    for ch in ("displacement", "force"):
        assert ident.after[0].nrmse(ch) <= ident.before[0].nrmse(ch) * (1 + 1e-9), ch
    assert ident.costs["frequency"] > ident.costs["start"]  # the trap is still there; the result avoids it


def test_a_fit_that_cannot_improve_says_so():
    """A key the records do not see (loop_delay with the effect off) cannot lower the cost: the
    result is the start, ``kept`` says so, and so does a flag."""
    rig = sh.zhao2003()
    rig.loop_delay = 0.002
    rec = chirp_record(rig, seed=1)
    ident = sh.identify([rec], rig=rig, fit=["loop_delay"], mode="displacement", progress=False,
                        frequency_stage=False, max_nfev=3, channels=["displacement"])
    assert ident.kept == "start" and ident.costs["time"] == ident.costs["start"]
    assert any(f.startswith("the fit could not improve on its start") for f in ident.flags), ident.flags
    assert ident.values["loop_delay"] == 0.002


def test_a_key_the_records_do_not_constrain_is_not_identified(tmp_path):
    """Issue 26, defect 2: loop_delay with the effect off does not change the simulation; it was
    reported as [0.002, 0.002].  Now: status "not identified", an infinite interval, null in the
    JSON, a flag, and a symmetric correlation matrix with |corr| <= 1."""
    import json

    rig = sh.zhao2003()
    rig.loop_delay = 0.002
    rec = chirp_record(rig, seed=2)
    ident = sh.identify([rec], rig=rig, fit=["G_p", "loop_delay"], mode="displacement", progress=False,
                        frequency_stage=False, max_nfev=4, channels=["displacement"])
    assert ident.status == {"G_p": "identified", "loop_delay": "not identified"}
    lo, hi = ident.intervals["loop_delay"]
    assert lo == 0.0 and hi == np.inf
    assert np.isfinite(ident.intervals["G_p"]).all() and ident.intervals["G_p"][0] < ident.values["G_p"]
    assert any(f.startswith("loop_delay is not identified") for f in ident.flags)
    d = json.loads(json.dumps(ident.to_dict(), default=float).replace("Infinity", "null").replace("NaN", "null"))
    assert d["parameters"]["loop_delay"]["status"] == "not identified"
    ident.write(tmp_path)
    written = json.loads((tmp_path / "identification.json").read_text())
    assert written["parameters"]["loop_delay"]["interval"] == [0.0, None]
    m = written["correlation"]["matrix"]
    assert m[0][0] == 1.0 and m[0][1] is None and m[1][0] is None


def test_identify_and_diagnose_give_the_same_interval_for_the_same_fit():
    """The same keys (the servovalve's f_v, zeta_v) fitted on the same simulated record (the
    displacement channel with AR(1) noise, phi = 0.9; truth 30 Hz, 0.7) from the same nominal rig
    (40 Hz) by ``sh.identify`` (log coordinates, the record's initial displacement fixed) and by
    ``sh.diagnose`` (its servovalve_dynamics candidate: reciprocal f_v, the initial displacement
    co-fitted): both take their 95 % intervals from ``stats.covariance``, so the intervals agree
    to the differences of the two fits, each end within 3 % of the interval's width.  (With the
    two rules of before, the AR(1)-inflated s^2 (J'J)^-1 of ``sh.identify`` gave f_v
    [29.899, 30.057] against the diagnosis's HAC [29.909, 30.047]: 7 % of the width apart.)"""
    truth = sh.zhao2003()
    truth.f_v, truth.zeta_v = 30.0, 0.7  # a valve slow enough to be seen in a 20 Hz chirp
    clean = chirp_record(truth, sigma_x=0.0, sigma_f=0.0)
    noise = signal.lfilter([1.0], [1.0, -0.9], 2e-6 * np.random.default_rng(4).standard_normal(clean.time.size))
    rec = sh.Response({"time": clean.time, "command": clean.command, "displacement": clean.displacement + noise,
                       "force": np.zeros(clean.time.size)})
    nominal = sh.zhao2003()
    nominal.f_v, nominal.zeta_v = 40.0, 0.7
    ident = sh.identify([rec], rig=nominal, fit=["f_v", "zeta_v"], mode="displacement", channels=["displacement"],
                        frequency_stage=False, progress=False)
    d = sh.diagnose([rec], nominal, mode="displacement", candidates=["servovalve_dynamics"], progress=False).to_dict()
    assert d["verdict"] == "effect_found" and [e["name"] for e in d["effects"]] == ["servovalve_dynamics"]
    diag = d["effects"][0]["parameters"]
    for k in ("f_v", "zeta_v"):
        i_lo, i_hi = ident.intervals[k]
        d_lo, d_hi = diag[k]["interval_95"]
        width = i_hi - i_lo
        assert ident.status[k] == "identified" and 0 < width < 0.01 * ident.values[k], (k, ident.intervals[k])
        assert i_lo <= getattr(truth, k) <= i_hi, (k, ident.intervals[k])
        assert abs(d_lo - i_lo) < 0.03 * width and abs(d_hi - i_hi) < 0.03 * width, (k, (d_lo, d_hi), (i_lo, i_hi))


# --- the package: a plain function, deprecated aliases, no import cycle ------------------------

def test_identify_is_a_plain_function_and_the_old_names_are_deprecated_aliases():
    """``sh.identify`` is the package's function (no callable module, no class swap); the old
    module paths warn, naming the new one and the removal version.  (Importing the deprecated
    module ``servohydraulics.identify`` binds the package attribute to it, as any submodule
    import does; its warning says to use ``servohydraulics.identification``.)"""
    from servohydraulics import identification

    assert isinstance(sh.identify, types.FunctionType) and sh.identify is identification.identify
    code = ("import types, warnings, servohydraulics as sh\n"
            "assert isinstance(sh.identify, types.FunctionType), sh.identify\n"
            "for name in ('servohydraulics.identify', 'servohydraulics.lab'):\n"
            "    with warnings.catch_warnings(record=True) as w:\n"
            "        warnings.simplefilter('always')\n"
            "        __import__(name)\n"
            "    msg = [str(x.message) for x in w if issubclass(x.category, DeprecationWarning)]\n"
            "    assert any('servohydraulics.identification' in m and '0.3.0' in m for m in msg), (name, msg)\n"
            "from servohydraulics.identification import identify\n"
            "assert isinstance(identify, types.FunctionType)\n"
            "from servohydraulics.lab import keys, fitting\n"
            "from servohydraulics.identification import coordinates, fit\n"
            "assert keys is coordinates and fitting is fit\n"
            "from servohydraulics.identify import identify_first_order, fourier_ratio, ar1_effective_n\n")
    subprocess.run([sys.executable, "-c", code], check=True)


def _module_imports(path: Path, name: str, modules: set[str]) -> set[str]:
    """The package-internal modules ``name`` (the module in ``path``) imports, at module level or
    inside a function (the old cycle ran through a call: ``identify.py`` called into ``lab``, which
    imported ``identify.py``): ``from P import m`` counts as P.m when that is a module, else as P."""
    tree = ast.parse(path.read_text())
    pkg = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name in modules}
        elif isinstance(node, ast.ImportFrom):
            base = pkg
            for _ in range(node.level - 1):
                base = base.rpartition(".")[0]
            mod = (f"{base}.{node.module}" if node.module else base) if node.level else (node.module or "")
            out |= {f"{mod}.{a.name}" if f"{mod}.{a.name}" in modules else mod for a in node.names}
    return out & modules


def _import_graph() -> dict[str, set[str]]:
    names = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
        names[".".join(parts)] = path
    modules = set(names) | {"servohydraulics._core"}  # the compiled core imports nothing of ours
    graph = {n: _module_imports(p, n, modules) - {n} for n, p in names.items()}
    graph["servohydraulics._core"] = set()
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    out, state, stack = [], {}, []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(graph[n]):
            if state.get(m) == 1:
                out.append(stack[stack.index(m):] + [m])
            elif m not in state:
                visit(m)
        stack.pop()
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n)
    return out


def test_the_identification_modules_import_no_cycle():
    """Walk the package's imports: no cycle passes through identification, the deprecated aliases
    or the diagnosis, and identification imports none of them."""
    graph = _import_graph()
    ours = ("servohydraulics.identification", "servohydraulics.identify", "servohydraulics.lab",
            "servohydraulics.diagnosis")
    bad = [c for c in _cycles(graph) if any(n.startswith(ours) for n in c)]
    assert not bad, bad
    assert not any(m.startswith(("servohydraulics.diagnosis", "servohydraulics.lab", "servohydraulics.identify"))
                   for n in graph if n.startswith("servohydraulics.identification") for m in graph[n])


@pytest.mark.parametrize("first, second", [("servohydraulics.identification", "servohydraulics.diagnosis"),
                                           ("servohydraulics.diagnosis", "servohydraulics.identification"),
                                           ("servohydraulics.identification.stats", "servohydraulics.identification"),
                                           ("servohydraulics.identification.fit", "servohydraulics.identify"),
                                           ("servohydraulics.lab", "servohydraulics.identification.records")])
def test_modules_import_in_either_order_in_a_fresh_interpreter(first, second):
    code = (f"import warnings; warnings.simplefilter('ignore', DeprecationWarning)\n"
            f"import {first}\nimport {second}\nfrom servohydraulics.identification import identify\n"
            "assert callable(identify)\n")
    subprocess.run([sys.executable, "-c", code], check=True)
