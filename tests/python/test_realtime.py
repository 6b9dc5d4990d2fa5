"""servohydraulics.realtime.Pacer and ``servohydraulics latency`` against oracles
that hold on a loaded machine (no timing assertion): wait() never returns before
its deadline (on Python's own CLOCK_MONOTONIC), deadline k = start + k * period
exactly, an injected overrun is counted, the histogram's percentiles are the
nearest-rank latency's bin (numpy, method="inverted_cdf"), bad input names the
field, and SCHED_FIFO refused in a child process (RLIMIT_RTPRIO 0 and, as root,
no CAP_SYS_NICE) is reported with its errno while the loop runs."""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core, cli
from servohydraulics.realtime import PERCENTILES, Pacer


def test_wait_never_early_and_the_schedule_is_absolute():
    for period_ns, period in ((1_000_000, 1e-3), (None, 1 / 4096)):
        pacer = Pacer(period).start()
        start = pacer.start_ns
        for k in (1, 2, 3, 4, 5, 4096, 10**6, 4096 * 86400):
            # exact integer oracle: round(k * period) in ns (1/4096 s = 244140.625 ns, halves round up)
            expect = start + (k * period_ns if period_ns else (k * 244_140_625 + 500) // 1000)
            assert pacer.deadline_ns(k) == expect
        lat = []
        for k in range(1, 301):
            late = pacer.wait()
            now = time.monotonic_ns()
            assert now >= pacer.deadline_ns(k)  # Python's clock: never before the deadline
            assert late >= 0.0
            lat.append(late)
        pacer.stop()
        s = pacer.stats()
        assert s["samples"] == 300
        assert s["latency_us"]["min"] == pytest.approx(1e6 * min(lat), abs=1e-3)
        assert s["latency_us"]["max"] == pytest.approx(1e6 * max(lat), abs=1e-3)


def test_wait_before_start_and_after_stop_is_refused():
    pacer = Pacer(1e-3)
    with pytest.raises(RuntimeError, match="before start"):
        pacer.wait()
    with pacer:
        pacer.wait()
    with pytest.raises(RuntimeError, match="before start"):
        pacer.wait()
    assert pacer.stats()["samples"] == 1  # the statistics survive stop()


def test_overrun_is_counted_and_the_loop_catches_up():
    period = 0.02
    pacer = Pacer(period).start()
    pacer.wait()
    pacer.wait()
    time.sleep(2.5 * period)  # wait 2 returned at >= deadline 2: deadlines 3 and 4 pass during the step
    late = pacer.wait()
    pacer.wait()
    assert pacer.misses >= 2
    assert late >= 1.5 * period
    assert pacer.deadline_ns(5) == pacer.start_ns + 5 * 20_000_000  # the schedule did not move
    s = pacer.stats()
    assert s["misses"] == pacer.misses and s["samples"] == 4
    assert s["compute_us"]["max"] >= 2.5 * period * 1e6


def test_percentiles_are_the_nearest_rank_latency_bin():
    """The histogram's percentiles against numpy's of the raw latencies (nearest rank),
    within the bin: first on the pacer's own run, then on log-uniform draws."""
    H = _core.LatencyHistogram
    pacer = Pacer(2e-4).start()
    lat_ns = np.array([round(pacer.wait() * 1e9) for _ in range(2000)])
    pacer.stop()
    s = pacer.stats()["latency_us"]
    rng = np.random.default_rng(24)
    cases = [(lat_ns, s)]
    for _ in range(20):
        v = np.floor(10 ** rng.uniform(0, 8, rng.integers(1, 4000))).astype(np.int64)
        h = H()
        for x in v:
            h.add(int(x))
        cases.append((v, {"min": h.min / 1e3, "p50": h.quantile(0.5) / 1e3, "p99": h.quantile(0.99) / 1e3,
                          "p99.9": h.quantile(0.999) / 1e3, "max": h.max / 1e3}))
    for raw, got in cases:
        ordered = np.sort(raw)
        for name, per_mille in (("min", 0), ("p50", 500), ("p99", 990), ("p99.9", 999), ("max", 1000)):
            rank = max(1, -(-per_mille * raw.size // 1000))  # ceil(q n), exactly
            exact = int(ordered[rank - 1])
            if per_mille == 500:  # the same as numpy's nearest-rank percentile
                assert exact == int(np.percentile(raw, 50, method="inverted_cdf"))
            b = H.bin(exact)
            lo, hi = H.bin_lower(b), H.bin_upper(b)
            assert lo <= 1e3 * got[name] + 1e-6 and 1e3 * got[name] - 1e-6 <= hi, (name, exact, lo, hi, got[name])
    assert tuple(k for k in s if k != "mean") == PERCENTILES


@pytest.mark.parametrize(("period", "kwargs", "field"), [
    (0.0, {}, "period_s"), (-1e-3, {}, "period_s"), (float("nan"), {}, "period_s"), (1e3, {}, "period_s"),
    ("fast", {}, "period_s"),
    (1e-3, {"fifo_priority": 0}, "fifo_priority"), (1e-3, {"fifo_priority": 100}, "fifo_priority"),
    (1e-3, {"fifo_priority": -5}, "fifo_priority"), (1e-3, {"fifo_priority": 1.5}, "fifo_priority"),
    (1e-3, {"cpu": -1}, "cpu"), (1e-3, {"cpu": 100000}, "cpu"), (1e-3, {"cpu": os.cpu_count()}, "cpu"),
    (1e-3, {"cpu": True}, "cpu"),
])
def test_bad_input_names_the_field(period, kwargs, field):
    with pytest.raises(ValueError, match=f"invalid {field} = "):
        Pacer(period, **kwargs)


def test_stats_say_what_was_asked_and_granted():
    before = os.sched_getscheduler(0)
    with Pacer(1e-3, fifo_priority=5, cpu=0) as pacer:
        for _ in range(10):
            pacer.wait()
        during = os.sched_getscheduler(0)
    s = pacer.stats()
    assert s["mlockall"] is False and s["mlockall_reason"] == "not requested"
    assert s["fifo"] == (during == os.SCHED_FIFO)
    assert s["fifo_reason"].startswith("granted" if s["fifo"] else "pthread_setschedparam")
    assert os.sched_getscheduler(0) == before  # stop() restored the thread
    assert json.loads(json.dumps(s)) == s


_CHILD = """
import json
from servohydraulics.realtime import Pacer
with Pacer(1e-3, fifo_priority=50) as p:
    for _ in range(5):
        p.wait()
print(json.dumps(p.stats()))
"""


def test_fifo_refused_is_reported_with_its_reason():
    """A child under RLIMIT_RTPRIO 0 (and, as root, without CAP_SYS_NICE, through
    setpriv) cannot have SCHED_FIFO: stats() says so, with EPERM, and the loop ran."""
    cmd = [sys.executable, "-c", _CHILD]
    if os.geteuid() == 0:
        setpriv = shutil.which("setpriv")
        if setpriv is None:
            pytest.skip("root without setpriv: CAP_SYS_NICE cannot be dropped for the child")
        cmd = [setpriv, "--inh-caps=-sys_nice", "--bounding-set=-sys_nice", *cmd]
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(Path(sh.__file__).resolve().parent.parent),
                                         *filter(None, [env.get("PYTHONPATH")])])
    if env.get("SERVOHYDRAULICS_CORE_DIR"):
        env["SERVOHYDRAULICS_CORE_DIR"] = str(Path(env["SERVOHYDRAULICS_CORE_DIR"]).resolve())

    def lower_rtprio():
        resource.setrlimit(resource.RLIMIT_RTPRIO, (0, 0))

    res = subprocess.run(cmd, capture_output=True, text=True, env=env, preexec_fn=lower_rtprio, timeout=60)
    assert res.returncode == 0, res.stderr
    s = json.loads(res.stdout)
    assert s["samples"] == 5
    assert s["fifo"] is False
    assert "EPERM" in s["fifo_reason"] and "RLIMIT_RTPRIO" in s["fifo_reason"]


def test_latency_command_runs_and_writes_json(tmp_path, capsys):
    out = tmp_path / "lat.json"
    assert cli.main(["latency", "--rate", "2000", "--seconds", "0.05", "--plant", "--json", str(out)]) == 0
    r = json.loads(out.read_text())
    assert r["samples"] == 100 and r["rate_hz"] == 2000 and r["step"] == "plant" and r["plant_failures"] == 0
    assert r["latency_us"]["min"] >= 0.0
    assert r["compute_us"]["p50"] > 0.0
    assert "Misses:" in capsys.readouterr().out


@pytest.mark.parametrize(("argv", "text"), [
    (["--rate", "0"], "invalid --rate = 0"), (["--rate", "nan"], "invalid --rate"),
    (["--rate", "-2000"], "invalid --rate"), (["--rate", "1e9"], "invalid --rate"),
    (["--rate", "2000", "--seconds", "0"], "invalid --seconds"),
    (["--rate", "2000", "--seconds", "1e-5"], "invalid --seconds"),
    (["--rate", "2000", "--seconds", "0.01", "--fifo", "0"], "invalid fifo_priority = 0"),
    (["--rate", "2000", "--seconds", "0.01", "--fifo", "200"], "invalid fifo_priority = 200"),
    (["--rate", "2000", "--seconds", "0.01", "--cpu", "4096"], "invalid cpu = 4096"),
])
def test_latency_command_bad_input_exits_2(argv, text, capsys):
    assert cli.main(["latency", *argv]) == 2
    err = capsys.readouterr().err
    assert text in err and "Traceback" not in err
