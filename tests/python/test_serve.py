"""servohydraulics serve (issue 24): the site server driven by a client nobody here wrote
(OpenSeesPy's genericClient), and a remote site inside our own RTHS loop.  The server always
runs in its own process: OpenSeesPy holds the GIL while it waits on the network."""

from __future__ import annotations

import math
import re
import signal
import socket
import subprocess
import sys

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import rths
from servohydraulics.distributed import Action, ProtocolError, RemoteSite, Sizes, generic_client_sizes
from servohydraulics.distributed.frame import linear_specimen_rig
from servohydraulics.distributed.protocol import Codec, request
from servohydraulics.distributed.server import finish_server_process, start_server_process
from servohydraulics.distributed.site import tracking_delay

K = 700800.0  # the specimen's stiffness [N/m] (the rig's k)
@pytest.fixture
def linear_rig(tmp_path):
    """A rig whose specimen is a linear spring: friction and softening off, damping 0, a negligible mass."""
    return sh.save_rig(linear_specimen_rig(K), tmp_path / "linear.toml")


_RUNNING: list = []


@pytest.fixture(autouse=True)
def _no_server_left_behind():
    yield
    while _RUNNING:
        finish_server_process(_RUNNING.pop(), timeout=0.1)


def _start(*args):
    proc, port = start_server_process(*args)
    _RUNNING.append(proc)
    return proc, port


def _finish(proc, timeout=60.0, sig=None) -> str:
    _RUNNING.remove(proc)
    return finish_server_process(proc, timeout, sig)


# --- the protocol alone -----------------------------------------------------------------------------
def test_handshake_checks_name_the_size():
    assert generic_client_sizes(1).to_bytes() == Sizes.from_bytes(generic_client_sizes(1).to_bytes()).to_bytes()
    generic_client_sizes(1).check(1)
    bad = {
        "control size of displacement = 2": Sizes((2, 2, 2, 0, 1), (0, 0, 0, 2, 0), 256),
        "control size of force = 1": Sizes((1, 0, 0, 1, 1), (0, 0, 0, 1, 0), 256),
        "control size of time = 3": Sizes((1, 0, 0, 0, 3), (0, 0, 0, 1, 0), 256),
        "data_size = 2": Sizes((1, 1, 1, 0, 1), (0, 0, 0, 1, 0), 2),
        "data_size = 100000": Sizes((1, 1, 1, 0, 1), (0, 0, 0, 1, 0), 100000),
        "acquisition size of velocity = -1": Sizes((1, 0, 0, 0, 0), (0, -1, 0, 1, 0), 8),
    }
    for text, sizes in bad.items():
        with pytest.raises(ProtocolError, match=re.escape(text)):
            sizes.check(1)
    with pytest.raises(ProtocolError, match="handshake of 43 bytes"):
        Sizes.from_bytes(b"\0" * 43)


def test_codec_rejects_bad_messages_and_packs_replies():
    sizes = generic_client_sizes(2)
    c = Codec(sizes)
    action, p = c.decode(request(Action.SET_TRIAL_RESPONSE, sizes, displacement=[1.0, 2.0], velocity=[3, 4],
                                 acceleration=[5, 6], time=[0.25]))
    assert action == Action.SET_TRIAL_RESPONSE and p["displacement"].tolist() == [1, 2] and p["time"].tolist() == [0.25]
    with pytest.raises(ProtocolError, match="message of 8 bytes"):
        c.decode(b"\0" * 8)
    with pytest.raises(ProtocolError, match="unknown action code 4.0"):
        c.decode(request(4, sizes))
    with pytest.raises(ProtocolError, match=r"trial velocity\[1\] = nan"):
        c.decode(request(Action.SET_TRIAL_RESPONSE, sizes, velocity=[0.0, math.nan]))
    m = np.frombuffer(c.reply(np.array([[1.0, 2.0], [3.0, 4.0]])), dtype=float)
    assert m.size == 256 and m[:4].tolist() == [1.0, 3.0, 2.0, 4.0] and not m[4:].any()  # column-major


# --- a client nobody here wrote -----------------------------------------------------------------------
def test_opensees_frame_with_remote_ideal_specimen_equals_local_spring(linear_rig):
    """--actuator ideal, linear specimen: the frame with the remote brace (genericClient) and the
    same frame with a local zeroLength spring of the same k agree to round-off (here: exactly);
    the handshake is what the docs say OpenSeesPy sends; the remote force is k x."""
    frame = pytest.importorskip("servohydraulics.distributed.frame")
    pytest.importorskip("openseespy.opensees")
    local = frame.run_frame(local_k=K, duration=2.0)
    proc, port = _start("--rig", str(linear_rig), "--actuator", "ideal", "--max-clients", "1")
    remote = frame.run_frame(port=port, duration=2.0)
    log = _finish(proc)
    sizes = generic_client_sizes(1)
    assert f"handshake control {sizes.control}, acquisition {sizes.daq}, data_size {sizes.data_size}" in log
    assert "ended (stopped)" in log and proc.returncode == 0
    x = local["displacement"]
    assert np.abs(x[:, 0]).max() > 1e-3  # the frame moves (mm), so equality means something
    np.testing.assert_allclose(remote["displacement"], x, rtol=0, atol=1e-12 * np.abs(x).max())
    np.testing.assert_allclose(remote["force"], K * remote["displacement"][:, 0], rtol=1e-12, atol=1e-9)


def test_opensees_frame_with_the_papers_actuator_shows_tracking_error_and_delay(tmp_path):
    """--actuator model with the paper's rig (the RPsD specimen mass, 140 kg): the measured
    displacement lags the command by the servo loop's phase delay at the excitation frequency
    (the linearised loop's, some 65 ms at 2 Hz: why the paper compensates T_d = 68 ms), with a
    tracking error of percent, and the frame's response moves away from the ideal one."""
    frame = pytest.importorskip("servohydraulics.distributed.frame")
    pytest.importorskip("openseespy.opensees")
    rig = sh.zhao2003()
    rig.m = 140.0
    path = sh.save_rig(rig, tmp_path / "rig.toml")
    proc, port = _start("--rig", str(path), "--max-clients", "1", "--record", str(tmp_path / "rec"))
    remote = frame.run_frame(port=port, dt=0.005, duration=2.0)
    log = _finish(proc)
    assert "ended (stopped)" in log, log
    rec = sh.read_record(tmp_path / "rec" / "client_001.csv")
    t, u, x = rec.time, rec.command, rec.displacement
    assert np.allclose(np.diff(t), 5e-4) and len(t) == 400 * 10  # 10 controller samples per 5 ms step
    assert "trials deferred to the next step: 400" in log  # Newmark's corrector, at the predictor's time
    delay = tracking_delay(t, u, x)
    # oracle: the phase delay of the linearised displacement loop at the excitation's 2 Hz
    import control as ct
    w = 2 * math.pi * frame.FREQUENCY
    H = complex(ct.frequency_response(sh.linearize(rig, "displacement"), [w]).complex.ravel()[0])
    assert 0.6 < delay / (-np.angle(H) / w) < 1.4, (delay, -np.angle(H) / w)
    assert np.sqrt(np.mean((x - u) ** 2)) > 0.02 * np.sqrt(np.mean(u ** 2))  # a tracking error of percent
    ideal = frame.run_frame(local_k=rig.k, dt=0.005, duration=2.0)
    d = np.abs(remote["displacement"] - ideal["displacement"]).max()
    assert np.isfinite(remote["displacement"]).all() and d > 0.05 * np.abs(ideal["displacement"]).max()


# --- the other direction: a remote site in our loop ----------------------------------------------------
def test_remote_site_in_the_rths_loop_equals_the_local_plant(tmp_path):
    """The RTHS loop with our servo-hydraulic plant served by another process (RemoteSite) is
    the loop with the plant in-process, sample for sample (the same core, float64 on the wire)."""
    rig = sh.zhao2003()
    rig.m, rig.k, rig.c = 100.0, 1.0e6, 200.0  # test_rths's small specimen
    path = sh.save_rig(rig, tmp_path / "rig.toml")
    rec = rths.synthetic_record(duration=1.5)
    rec.time, rec.acceleration = rec.time[450:700] - 4.5, rec.acceleration[450:700]  # 0.5 s of zeros, the motion
    case = rths.embedded_case(1)
    local = rths.run_trial(case, rec, "sample", experimental=rths.core.ServoHydraulicSubstructure(rig, rths.DT),
                           seed=1, keep_signals=True)
    proc, port = _start("--rig", str(path), "--dt", repr(rths.DT), "--max-clients", "1")
    with RemoteSite("127.0.0.1", port, dt=rths.DT, specimen=(rig.m, rig.c, rig.k)) as site:
        remote = rths.run_trial(case, rec, "sample", experimental=site, seed=1, keep_signals=True)
    log = _finish(proc)
    assert local.ok and remote.ok and "ended (stopped)" in log
    n = len(local.response.time)
    assert n == len(remote.response.time) == rec.samples() and np.abs(local.response.actuator_force).max() > 100.0
    for ch in ("displacement", "actuator_force", "command", "measured", "feedback_force"):
        np.testing.assert_array_equal(getattr(remote.response, ch), getattr(local.response, ch), err_msg=ch)
    assert remote.J == local.J


def test_remote_site_failure_stops_the_loop_with_the_sites_reason(tmp_path, linear_rig):
    """A site that drops the connection (a trial beyond the stroke) fails the run with a message."""
    proc, port = _start("--rig", str(linear_rig), "--actuator", "ideal", "--max-clients", "1")
    with RemoteSite("127.0.0.1", port, dt=1e-3) as site:
        assert site.specimen() == (0.0, 0.0, K)  # from the site's initial stiffness (exact: a linear spring)
        site.step(0.01)
        assert site.actuator_force == pytest.approx(K * 0.01, rel=1e-15) and site.displacement == 0.01
        with pytest.raises(ConnectionError, match="closed the connection"):
            site.step(0.2)  # the stroke is 0.127 m
    log = _finish(proc)
    assert "trial displacement[0] = 0.2 m beyond the stroke +-0.127 m" in log


# --- safety ---------------------------------------------------------------------------------------------
def _connect(port):
    s = socket.create_connection(("127.0.0.1", port), timeout=10)
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return s


def _wait_closed(s) -> bool:
    """True when the server closes (EOF or reset) within the socket's timeout."""
    try:
        while s.recv(65536):
            pass
        return True
    except ConnectionResetError:
        return True
    except socket.timeout:
        return False
    finally:
        s.close()


def test_one_client_at_a_time_idle_timeout_and_ctrl_c(linear_rig):
    proc, port = _start("--rig", str(linear_rig), "--actuator", "ideal", "--timeout", "0.5")
    silent = _connect(port)
    second = _connect(port)  # refused while the silent one is served
    assert _wait_closed(second)
    assert _wait_closed(silent)  # dropped after --timeout
    with RemoteSite("127.0.0.1", port, dt=1e-3) as site:  # and the next client is served
        site.step(1e-3)
        assert site.actuator_force == pytest.approx(K * 1e-3, rel=1e-15)
    log = _finish(proc, 20, signal.SIGINT)
    assert proc.returncode == 130, log
    assert "busy with another client" in log and "(timeout): no data for 0.5 s" in log
    assert "stopped (interrupt)" in log and "interrupted" in log and "Traceback" not in log


def test_ctrl_c_stops_a_server_started_with_sigint_ignored(linear_rig):
    """A server started from a shell's background job inherits SIGINT ignored (no job control):
    it still stops on SIGINT with exit 130 (it failed CI that way: killed after 20 s)."""
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        proc, _ = _start("--rig", str(linear_rig), "--actuator", "ideal")
    finally:
        signal.signal(signal.SIGINT, old)
    log = _finish(proc, 20, signal.SIGINT)
    assert proc.returncode == 130, log
    assert "stopped (interrupt)" in log and "Traceback" not in log


@pytest.mark.parametrize("args, text", [
    (["--port", "70000"], "--port = 70000"),
    (["--port", "0", "--actuators", "0"], "--actuators = 0"),
    (["--port", "0", "--actuator", "ideal", "--realtime"], "need --actuator model"),
    (["--port", "0", "--rig", "/nonexistent.toml"], "rig file not found"),
])
def test_cli_bad_input_exits_2_naming_it(args, text):
    res = subprocess.run([sys.executable, "-m", "servohydraulics", "serve", *args], capture_output=True, text=True,
                         timeout=60)
    assert res.returncode == 2 and text in res.stderr and "Traceback" not in res.stderr, res.stderr


def test_ideal_refuses_a_specimen_with_a_state(tmp_path):
    rig = sh.zhao2003()
    rig.effects.bouc_wen_hysteresis = True
    path = sh.save_rig(rig, tmp_path / "bw.toml")
    res = subprocess.run([sys.executable, "-m", "servohydraulics", "serve", "--port", "0", "--rig", str(path),
                          "--actuator", "ideal"], capture_output=True, text=True, timeout=60)
    assert res.returncode == 2 and "bouc_wen_hysteresis" in res.stderr


def test_distributed_frame_example_compensation_brings_the_frame_back():
    """examples/11_distributed_frame.py: the actuator's delay changes the frame's response; the
    paper's amplitude compensation (serve --controller lead) shortens the delay and brings it back
    towards the ideal brace's."""
    pytest.importorskip("openseespy.opensees")
    from pathlib import Path
    ex = Path(__file__).resolve().parents[2] / "examples" / "11_distributed_frame.py"
    res = subprocess.run([sys.executable, str(ex), "2.5"], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    s = dict(kv.split("=") for kv in res.stdout.split() if "=" in kv)
    v = {k: float(x) for k, x in s.items()}
    assert v["lead_delay_ms"] < 0.5 * v["none_delay_ms"]
    assert v["lead_vs_ideal_pct"] < 0.5 * v["none_vs_ideal_pct"]
    assert v["lead_tracking_error_pct"] < v["none_tracking_error_pct"]


def test_model_site_paces_every_controller_sample_and_moves_on_request():
    """--realtime's pacing contract (servohydraulics.realtime.Pacer: start() per connection,
    wait() before every controller sample, stats() logged), and when the model moves: on a
    request for the response, over the client's time step; a trial at an unchanged time waits."""
    from servohydraulics.distributed import ModelSite

    class Pacer:
        def __init__(self):
            self.starts = self.waits = 0

        def start(self):
            self.starts += 1

        def wait(self):
            self.waits += 1
            return 0.0

        def stats(self):
            return {"waits": self.waits}

    pacer = Pacer()
    site = ModelSite(sh.zhao2003(), pacer=pacer)  # dt 0.5 ms
    assert pacer.starts == 1
    site.set_trial({"displacement": np.array([1e-3])}, 0.01)
    assert pacer.waits == 0  # nothing moves before the client asks
    r = site.response()
    assert pacer.waits == 20 and r["time"][0] == pytest.approx(0.01) and 0 < r["displacement"][0] < 1e-3
    site.set_trial({"displacement": np.array([2e-3])}, 0.01)  # the corrector, at the same time
    site.response()
    assert pacer.waits == 20 and site.deferred == 1
    site.set_trial({"displacement": np.array([2e-3])}, 0.015)
    site.response()
    assert pacer.waits == 30 and site.close() == {"controller samples": 30, "trials deferred to the next step": 1,
                                                   "pacing": {"waits": 30}}
    site.reset()
    assert pacer.starts == 2


def test_serve_realtime_paces_with_the_real_pacer_and_changes_no_digit(tmp_path):
    """serve --realtime with servohydraulics.realtime.Pacer: the frame's response is the unpaced
    run's to the bit (pacing only waits), every controller sample was paced (the log's pacing
    stats count them: 10 per 5 ms step, 100 steps), and the client's wall time covers them
    (absolute deadlines: n periods cannot pass in less than n * dt)."""
    import time

    frame = pytest.importorskip("servohydraulics.distributed.frame")
    pytest.importorskip("openseespy.opensees")
    rig = sh.zhao2003()
    rig.m = 140.0
    path = str(sh.save_rig(rig, tmp_path / "rig.toml"))
    free = frame.run_frame_served("--rig", path, dt=0.005, duration=0.5)
    t0 = time.monotonic()
    paced = frame.run_frame_served("--rig", path, "--realtime", dt=0.005, duration=0.5)
    wall = time.monotonic() - t0
    np.testing.assert_array_equal(paced["displacement"], free["displacement"])
    np.testing.assert_array_equal(paced["force"], free["force"])
    m = re.search(r"'samples': (\d+), 'misses': (\d+)", paced["log"])
    assert m, paced["log"]
    assert int(m.group(1)) == 1000 and wall >= 1000 * 5e-4


def test_tracking_delay_finds_a_known_lag():
    t = np.arange(4000) * 5e-4
    u = np.sin(2 * math.pi * 2.0 * t) + 0.3 * np.sin(2 * math.pi * 5.3 * t)
    assert tracking_delay(t, u, np.interp(t - 0.0375, t, u)) == pytest.approx(0.0375)


def test_ideal_site_of_two_actuators_answers_each_spring(linear_rig):
    """--actuators 2: each element DOF its own specimen against the ground: force k x per DOF, a
    diagonal stiffness, column-major on the wire; a client of the wrong size is refused."""
    from servohydraulics.distributed import IdealSite

    site = IdealSite(sh.load_rig(linear_rig), 2)
    sizes = generic_client_sizes(2)
    c = Codec(sizes)
    _, p = c.decode(request(Action.SET_TRIAL_RESPONSE, sizes, displacement=[1e-3, -2e-3], time=[0.01]))
    site.set_trial(p, 0.01)
    f = np.frombuffer(c.reply(site.response()["force"]), dtype=float)
    assert f[:2].tolist() == [K * 1e-3, -K * 2e-3] and not f[2:].any()
    k = np.frombuffer(c.reply(site.matrix(Action.GET_TANGENT_STIFFNESS)), dtype=float)
    assert k[:4].tolist() == [K, 0.0, 0.0, K]
    with pytest.raises(ProtocolError, match="control size of displacement = 1"):
        generic_client_sizes(1).check(2)


def test_python_experimental_substructure_failure_names_the_time():
    """rths.run_trial(experimental=<a Python object>): what it raises stops the loop and comes
    back as an error naming the sample's time (the binding's PythonExperimentalSubstructure)."""

    class Failing:
        dt = rths.DT
        displacement = velocity = actuator_force = 0.0

        def specimen(self):
            return (29.13, 0.0, 1.19e6)

        def reset(self):
            self.k = 0

        def step(self, command):
            self.k += 1
            if self.k == 100:
                raise ConnectionError("the site went away")

    rec = rths.synthetic_record(duration=0.5)
    with pytest.raises(RuntimeError, match=r"experimental substructure failed at t = 0.024[0-9]* s: "
                                           r"ConnectionError: the site went away$"):
        rths.run_trial(rths.embedded_case(1), rec, "sample", experimental=Failing())


@pytest.mark.parametrize("restoring_force", ["measured_displacement", "measured_force_corrected"])
def test_rpsd_by_hand_against_a_remote_site_equals_run_rpsd(tmp_path, restoring_force):
    """The RPsD controller stepped by hand against the paper's rig served by another process
    (RemoteSite.sensors() as its sensors) is sh.run_rpsd with the rig in-process, sample for
    sample: the controller/plant seam across the network."""
    rig = sh.zhao2003()
    path = sh.save_rig(rig, tmp_path / "rig.toml")
    n, dt = 1000, 5e-4
    t = np.arange(n) * dt
    ag = 1.0 * np.sin(2 * math.pi * 1.1 * t) * np.minimum(1.0, t / 0.2)
    res = sh.run_rpsd(rig, ground_acceleration=ag, restoring_force=restoring_force)
    ctrl = sh.RpsdController(rig, restoring_force=restoring_force)
    proc, port = _start("--rig", str(path), "--max-clients", "1")
    commands, measured = np.empty(n), np.empty(n)
    with RemoteSite("127.0.0.1", port, dt=dt, specimen=(rig.m, rig.c, rig.k)) as site:
        sensors = site.sensors()
        for k in range(n):
            commands[k], measured[k] = ctrl.command(sensors, ground_acceleration=ag[k]), sensors.displacement
            site.step(commands[k])
            sensors = site.sensors()
    assert "ended (stopped)" in _finish(proc)
    assert np.abs(res.displacement).max() > 1e-3
    np.testing.assert_array_equal(commands, res.command)
    np.testing.assert_array_equal(measured, res.displacement)


def test_output_from_channels_names_a_wrong_channel():
    o = sh._core.Output.from_channels(displacement=0.25, force=-3.0)
    assert (o.displacement, o.force, o.velocity) == (0.25, -3.0, 0.0)
    with pytest.raises(ValueError, match="unknown plant channel pressur: expected one of time, displacement"):
        sh._core.Output.from_channels(pressur=1.0)
