"""Pictures a lab engineer reads (issue 25, item 5): the zoom windows find where model and
data part (the oracle: a discrepancy put there), the FRF does not draw the measured estimate
where its coherence is low, the loops and the RTHS report's figures carry their names."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

from servohydraulics.identification.figures import (
    ENVELOPE_RUNS,
    MIN_COHERENCE,
    envelope,
    frf_figure,
    loops_figure,
    overlay_figure,
    zoom_windows,
)
from servohydraulics.identification.frf import h1

DT = 1e-3


def _chirp(n: int = 60000) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * DT
    f = 0.2 + 15.0 * t / t[-1]
    return t, 0.002 * np.sin(2 * np.pi * np.cumsum(f) * DT)


def test_zoom_windows_find_where_the_records_part():
    t, u = _chirp()
    x = 0.9 * u
    sim = x.copy()
    sim[41000:41800] += 4e-4 * np.sin(np.linspace(0, 6 * np.pi, 800))  # the model departs here
    sim[12000:12300] += 1e-4
    sim[25000:25200] += 5e-5
    wins = zoom_windows(t, {"displacement": x}, {"displacement": sim}, u, 4)
    assert len(wins) == 3 and wins == sorted(wins)  # three places part, a fourth window has nothing to show
    for spot in (12150, 25100, 41400):
        assert any(a <= spot <= b for a, b in wins), (spot, wins)
    hit = [a <= 41400 <= b for a, b in wins]
    a, b = wins[hit.index(True)]
    period = 1.0 / (0.2 + 15.0 * 41.4 / 60.0)
    assert 2.0 * period / DT < b - a < 8.0 * period / DT  # about four cycles of the command there
    for (_, b1), (a2, _) in zip(wins, wins[1:]):
        assert b1 <= a2  # not overlapping
    fig = overlay_figure(t, {"displacement": x}, {"displacement": sim}, "test", command=u)
    assert isinstance(fig, Figure)
    titles = [ax.get_title() for ax in fig.axes]
    assert sum(ttl[:2] in ("A:", "B:", "C:") for ttl in titles) == 3


def test_a_long_trace_is_drawn_through_the_extremes_of_each_run_of_samples():
    """Oracle: the trace itself.  The envelope drawn for a 61,501-sample chirp with a spike and a
    NaN is a time-ordered subsequence of it with at most four samples per run; in each run of
    samples it holds that run's first, last, lowest and highest sample (so the drawn extremes are
    the trace's, to the sample), and the NaN (the line breaks there); a short trace is drawn whole."""
    t, y = _chirp(61501)
    y[123] = 0.05
    y[40000] = np.nan
    tt, yy = envelope(t, y)
    idx = np.searchsorted(t, tt)
    assert np.all(np.diff(idx) > 0) and np.array_equal(t[idx], tt)
    np.testing.assert_array_equal(yy, y[idx])
    assert tt.size <= 4 * ENVELOPE_RUNS
    edges = np.linspace(0, y.size, ENVELOPE_RUNS + 1).astype(int)
    for a, b in zip(edges[:-1], edges[1:]):
        kept = idx[(idx >= a) & (idx < b)]
        run = y[a:b]
        assert a in kept and b - 1 in kept
        if np.isnan(run).any():
            assert a + int(np.flatnonzero(np.isnan(run))[0]) in kept
        else:
            assert y[kept].max() == run.max() and y[kept].min() == run.min()
    t2, y2 = envelope(t[:400], y[:400])
    assert np.array_equal(t2, t[:400]) and np.array_equal(y2, y[:400])


def test_frf_masks_low_coherence_bands():
    rng = np.random.default_rng(0)
    n = 60000
    u = rng.standard_normal(n)
    from scipy import signal

    b, a = signal.butter(4, 2 * 10.0 * DT)
    u = signal.lfilter(b, a, u)  # energy below 10 Hz only: above it the coherence falls
    y = signal.lfilter(*signal.butter(2, 2 * 30.0 * DT), u) + 0.02 * np.std(u) * rng.standard_normal(n)
    hm, hs = h1(u, y, DT), h1(u, signal.lfilter(*signal.butter(2, 2 * 30.0 * DT), u), DT)
    fig = frf_figure({"displacement": hm}, {"displacement": hs}, 40.0, "test")
    gain_ax = fig.axes[0]
    measured = next(ln for ln in gain_ax.get_lines() if ln.get_label() == "measured")
    f, g = measured.get_xdata(), measured.get_ydata()
    coh = np.interp(f, hm.frequency, hm.coherence)
    assert np.all(np.isnan(g[coh < MIN_COHERENCE - 1e-9]))
    assert np.all(np.isfinite(g[coh >= MIN_COHERENCE + 1e-9]))
    assert (coh < MIN_COHERENCE).any() and (coh >= MIN_COHERENCE).any()
    spans = [p for p in gain_ax.patches]
    assert spans, "no greyed band"
    simulated = next(ln for ln in gain_ax.get_lines() if ln.get_label() == "simulated")
    assert np.all(np.isfinite(simulated.get_ydata()))  # the model is drawn everywhere


def test_loops_figure_has_force_displacement_and_force_velocity():
    t, u = _chirp(20000)
    x = 0.95 * u
    v = np.gradient(x, DT)
    f = 2000 * np.tanh(v / 0.01) + 1e5 * x
    fig = loops_figure(t, {"displacement": x, "force": f}, {"displacement": x, "force": 1.1 * f}, "damper", command=u)
    labels = [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes]
    assert labels.count(("displacement [mm]", "force [kN]")) == 2
    assert labels.count(("velocity [mm/s]", "force [kN]")) == 2


def test_rths_figures_are_titled_and_name_the_criteria():
    from servohydraulics.rths.evaluation import J_LABELS
    from servohydraulics.rths.figures import criteria_figure, synchronization_figure, tracking_figure

    class _Trial:
        J = [4.6, 10.4, 11.5, 36.1, 19.0, 32.3, 32.4, 14.8, 14.8]

        def __init__(self):
            t = np.arange(4000) / 4096
            y = 0.01 * np.sin(2 * np.pi * t)
            self.signals = {"time": t, "numerical": y[:, None], "measured": np.roll(y, 19),
                            "reference": y[:, None]}

    meta = {"record": "elcentro", "eq_intensity": 0.4, "controller": "sample", "synthetic": False}
    trials = {1: _Trial(), 2: _Trial()}
    results = {"meta": meta, "cases": {str(n): {"nominal": {"J": tr.J}} for n, tr in trials.items()}}
    for fig in (tracking_figure(trials, meta), synchronization_figure(trials, meta), criteria_figure(results)):
        assert "RTHS benchmark" in fig._suptitle.get_text() and "elcentro x 0.4" in fig._suptitle.get_text()
    ticks = [tk.get_text() for ax in criteria_figure(results).axes for tk in ax.get_yticklabels()]
    assert all(label in ticks for label in J_LABELS[1:])
    err = tracking_figure(trials, meta).axes[1]
    assert err.get_ylabel().startswith("tracking error")
    sync = synchronization_figure(trials, meta).axes[0]
    assert sync.get_xlabel() == "desired y_n(1) [mm]" and sync.get_ylabel() == "measured x_m [mm]"


@pytest.mark.parametrize("n", [384, 1000])
def test_short_records_still_draw(n):
    t, u = _chirp(n)
    fig = overlay_figure(t, {"displacement": u, "force": 1e5 * u}, {"displacement": 1.01 * u, "force": 1e5 * u},
                         "short", command=u)
    assert isinstance(fig, Figure)
