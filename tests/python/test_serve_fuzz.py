"""Fuzzing servohydraulics serve (issue 24, item 6): 1,200 malformed client connections from a
seeded generator against one server process; each must end with the server closing it (a
logged reason), never a crash or a hang, and a good client is served correctly afterwards."""

from __future__ import annotations

import re
import signal
import socket
import struct
import time
from collections import Counter

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.distributed import Action, RemoteSite, generic_client_sizes
from servohydraulics.distributed.frame import linear_specimen_rig
from servohydraulics.distributed.protocol import request
from servohydraulics.distributed.server import finish_server_process, server_log, start_server_process

K = 700800.0
GOOD = generic_client_sizes(1)
CONNECTIONS = 1200
SILENT = 4  # clients that send nothing: each costs the server's --timeout


def _trial(**values) -> bytes:
    return request(Action.SET_TRIAL_RESPONSE, GOOD, **values)


def _cases(rng: np.random.Generator):
    """(kind, bytes to send, how the client ends: 'half-close' | 'reset' | 'silent')."""
    hs = GOOD.to_bytes()
    n = GOOD.message_bytes
    kinds = ["short handshake", "bad sizes", "huge data_size", "short message", "unknown code", "non-finite trial",
             "beyond stroke", "time backwards", "garbage", "dies mid-message"]
    for i in range(CONNECTIONS):
        kind = kinds[i % len(kinds)] if i >= SILENT else "silent"
        if kind == "silent":
            yield kind, b"", "silent"
        elif kind == "short handshake":
            yield kind, hs[: int(rng.integers(0, len(hs)))], "half-close"
        elif kind == "bad sizes":
            v = [int(x) for x in rng.integers(-5, 9, size=11)]
            v[10] = int(rng.integers(-2**31, 2**31 - 1)) if rng.random() < 0.5 else v[10]
            yield kind, struct.pack("=11i", *v), "half-close"
        elif kind == "huge data_size":
            yield kind, struct.pack("=11i", *GOOD.control, *GOOD.daq, int(rng.integers(65537, 2**31 - 1))), \
                "half-close"
        elif kind == "short message":
            yield kind, hs + _trial(displacement=[1e-3], time=[0.01])[: int(rng.integers(1, n))], "half-close"
        elif kind == "unknown code":
            code = float(rng.choice([0.0, 1.0, 4.0, 16.0, 98.0, 3.5, -3.0, 1e300, np.nan, np.inf]))
            yield kind, hs + np.r_[code, np.zeros(GOOD.data_size - 1)].tobytes(), "half-close"
        elif kind == "non-finite trial":
            bad = float(rng.choice([np.nan, np.inf, -np.inf]))
            which = str(rng.choice(["displacement", "velocity", "acceleration", "time"]))
            yield kind, hs + _trial(**{which: [bad]}), "half-close"
        elif kind == "beyond stroke":
            x = float(rng.choice([-1.0, 1.0])) * float(rng.uniform(0.1271, 1e6))
            yield kind, hs + _trial(displacement=[x], time=[0.01]), "half-close"
        elif kind == "time backwards":
            yield kind, hs + _trial(displacement=[1e-3], time=[0.02]) + _trial(displacement=[1e-3], time=[0.01]), \
                "half-close"
        elif kind == "garbage":
            yield kind, hs[:44] * (rng.random() < 0.5) + rng.bytes(int(rng.integers(1, 3 * n))), "half-close"
        else:  # dies mid-message: an RST in the middle of a request
            yield kind, hs + _trial(displacement=[1e-3], time=[0.01])[: int(rng.integers(1, n))], "reset"


def _run_client(port: int, data: bytes, end: str) -> str:
    """What the client saw: 'closed by server' (EOF or reset), or 'reset sent'."""
    s = socket.create_connection(("127.0.0.1", port), timeout=10)
    try:
        if data:
            try:
                s.sendall(data)
            except OSError:  # the server may close as soon as it has read enough to object
                return "closed by server"
        if end == "reset":
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            return "reset sent"
        if end == "half-close":
            try:
                s.shutdown(socket.SHUT_WR)
            except OSError:  # already reset by the server
                return "closed by server"
        while True:
            try:
                if not s.recv(65536):
                    return "closed by server"
            except ConnectionResetError:
                return "closed by server"
            except socket.timeout:
                return "hang"
    finally:
        s.close()


def test_a_thousand_malformed_clients_then_a_good_one(tmp_path):
    rig = sh.save_rig(linear_specimen_rig(K), tmp_path / "linear.toml")
    proc, port = start_server_process("--rig", str(rig), "--actuator", "ideal", "--timeout", "0.3")
    try:
        rng = np.random.default_rng(24)
        seen = Counter()
        t0 = time.perf_counter()
        for kind, data, end in _cases(rng):
            seen[(kind, _run_client(port, data, end))] += 1
            if end == "reset":
                time.sleep(0.002)  # let the server see the reset before the next client (else: refused)
        wall = time.perf_counter() - t0
        assert proc.poll() is None  # still serving
        assert not [k for k in seen if k[1] == "hang"], seen
        with RemoteSite("127.0.0.1", port, dt=1e-3) as site:  # and a good client is served correctly
            site.step(0.004)
            assert site.actuator_force == pytest.approx(K * 0.004, rel=1e-15)
        deadline = time.monotonic() + 10
        while "ended (stopped)" not in server_log(proc) and time.monotonic() < deadline:
            time.sleep(0.01)  # the server logs the good client's stop before we stop it
    finally:
        log = finish_server_process(proc, 20, signal.SIGTERM)
    summary = re.search(r"stopped \(interrupt\): (\d+) client\(s\), (\d+) refused; (.*)", log)
    assert summary, log[-3000:]
    clients, refused = int(summary.group(1)), int(summary.group(2))
    outcomes = {k.strip(): int(v) for k, v in re.findall(r"([a-z ]+): (\d+)", summary.group(3))}
    assert clients + refused == CONNECTIONS + 1 and clients >= 1000
    assert outcomes.get("stopped") == 1  # only the good client ended with stop
    assert outcomes.get("timeout") == SILENT
    assert sum(outcomes.values()) == clients
    assert "Traceback" not in log and "internal error" not in log
    print(f"\n{CONNECTIONS} malformed connections in {wall:.1f} s; server outcomes {outcomes}, refused {refused}; "
          f"client side {dict(Counter(v for (_, v) in seen.elements()))}")
