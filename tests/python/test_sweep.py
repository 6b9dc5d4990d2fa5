"""sh.sweep: grids and seeded Monte Carlo draws over rig parameters, run through
process pools, a thread pool and a local Dask cluster.

Physics oracle: at a low frequency the displacement loop (Eqs 1-4 with the
valve and compressibility neglected, Eq 8) is a first-order lag with the
crossover omega_c = C_F G_p K_s K_v / A, so the tracking error of a sine
u = a sin(w t) is a w / sqrt(w^2 + omega_c^2) in amplitude: its RMS falls
like 1/G_p.  The sweep over G_p must reproduce that closed form.
"""

from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest
from scipy import stats

import servohydraulics as sh
from servohydraulics.parameter_sweep import summary_run

AMPLITUDE = 2e-3  # [m]: small, the flow curve and friction stay negligible
FREQUENCY = 0.5  # [Hz]
DURATION = 4.0  # [s]
FIXED = {"amplitude": AMPLITUDE, "frequency": FREQUENCY, "duration": DURATION}
G_P = [0.4, 0.8, 1.6]


def crossover(rig: sh.Rig) -> float:
    """omega_c of the first-order displacement loop [rad/s] (Eq 8, valve and
    compressibility neglected)."""
    return rig.C_F_disp * rig.G_p * rig.K_s * rig.K_v / rig.A


def expected_rms_error(rig: sh.Rig) -> float:
    w = 2 * math.pi * FREQUENCY
    wc = crossover(rig)
    return AMPLITUDE * w / math.sqrt(w * w + wc * wc) / math.sqrt(2)


METRICS = ["ok", "peak_displacement", "peak_force", "rms_tracking_error", "internal_steps"]


@pytest.fixture(scope="module")
def grid_result():
    with ProcessPoolExecutor(max_workers=2) as ex:
        return sh.sweep(grid={"controller.G_p": G_P}, fixed=FIXED, executor=ex, progress=False)


def test_grid_matches_first_order_loop(grid_result):
    df = grid_result
    assert list(df["controller.G_p"]) == G_P
    assert df["ok"].all()
    for _, row in df.iterrows():
        rig = sh.zhao2003()
        rig.G_p = row["controller.G_p"]
        # The start-up transient and the neglected valve lag: 15 %.
        assert row["rms_tracking_error"] == pytest.approx(expected_rms_error(rig), rel=0.15)
        w, wc = 2 * math.pi * FREQUENCY, crossover(rig)
        assert row["peak_displacement"] == pytest.approx(AMPLITUDE * wc / math.hypot(w, wc), rel=0.1)


def test_grid_runs_equal_serial_runs(grid_result):
    """The pool changes where runs happen, not what they compute (bit-identical)."""
    for _, row in grid_result.iterrows():
        rig = sh.zhao2003()
        rig.G_p = row["controller.G_p"]
        serial = summary_run(rig, **FIXED)
        for m in METRICS:
            assert row[m] == serial[m], m


def test_dask_local_cluster_gives_the_same_rows(grid_result):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        df = sh.sweep(grid={"controller.G_p": G_P}, fixed=FIXED, executor=client.get_executor(), progress=False)
    for m in METRICS:
        assert list(df[m]) == list(grid_result[m]), m


def test_monte_carlo_draws_are_seeded_and_recorded():
    dists = {"structure.m": stats.uniform(loc=5000.0, scale=4000.0), "controller.G_p": stats.norm(0.8, 0.05)}
    kw = {"distributions": dists, "n": 3, "fixed": {"duration": 0.2}, "executor": ThreadPoolExecutor(2),
          "progress": False}
    a = sh.sweep(seed=7, **kw)
    b = sh.sweep(seed=7, **kw)
    c = sh.sweep(seed=8, **kw)
    rng = np.random.default_rng(7)
    m = dists["structure.m"].rvs(size=3, random_state=rng)
    gp = dists["controller.G_p"].rvs(size=3, random_state=rng)
    np.testing.assert_array_equal(a["structure.m"], m)
    np.testing.assert_array_equal(a["controller.G_p"], gp)
    assert a.equals(b.assign(wall_time=a["wall_time"]))
    assert not np.array_equal(a["structure.m"], c["structure.m"])
    # Mass changes the force needed for the same motion: F ~ k x + M a.
    assert a["ok"].all()


def test_grid_and_draws_combine():
    df = sh.sweep(grid={"controller.G_p": [0.6, 0.9]}, distributions={"structure.c": lambda rng: rng.uniform(1e3, 3e3)},
                  n=2, fixed={"duration": 0.1}, executor=ThreadPoolExecutor(2), progress=False)
    assert len(df) == 4
    assert list(df["controller.G_p"]) == [0.6, 0.6, 0.9, 0.9]
    assert list(df["structure.c"][:2]) == list(df["structure.c"][2:])


def test_bad_names_and_values_fail_before_running():
    with pytest.raises(ValueError, match="structure.mass"):
        sh.sweep(grid={"structure.mass": [1.0]}, executor=ThreadPoolExecutor(1), progress=False)
    with pytest.raises(ValueError, match="m"):
        sh.sweep(grid={"structure.m": [-1.0]}, executor=ThreadPoolExecutor(1), progress=False)
    with pytest.raises(ValueError, match="n"):
        sh.sweep(distributions={"structure.m": stats.norm(7000, 10)}, progress=False)
    with pytest.raises(ValueError, match="grid"):
        sh.sweep(progress=False)


def failing_run(rig: sh.Rig, x: float) -> dict:
    if x > 0:
        raise RuntimeError("boom")
    return {"value": rig.m * x}


def test_a_failing_run_is_a_row_with_an_error():
    df = sh.sweep(grid={"x": [0.0, 1.0]}, run=failing_run, executor=ThreadPoolExecutor(1), progress=False)
    assert df.loc[0, "value"] == 0.0
    assert "boom" in df.loc[1, "error"]


def test_keep_records_returns_the_simulation():
    df = sh.sweep(grid={"controller.G_p": [0.8]}, fixed={"duration": 0.1}, keep_records=True,
                  executor=ThreadPoolExecutor(1), progress=False)
    rec = df.loc[0, "record"]
    assert isinstance(rec, sh.Response) and rec.kind == "plant"
    assert rec.displacement.max() == pytest.approx(df.loc[0, "peak_displacement"])
