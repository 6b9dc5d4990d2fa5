"""The site server: one client at a time over TCP, the wire protocol of protocol.py.

Safe by default: it binds 127.0.0.1; a malformed handshake or message, a non-finite or
beyond-stroke trial, a plant failure, a client that dies or stays silent longer than
``timeout``: each ends that connection with one logged reason and the server waits for the
next.  A second client while one is served is accepted and closed at once (logged as
refused).  Ctrl-C (or SIGTERM) closes everything and returns.

Latency: the server sets TCP_NODELAY and, after every read, TCP_QUICKACK (Linux), so that
a client that leaves Nagle's algorithm on (OpenSees does) never waits for our delayed
acknowledgement of a request that has no reply (docs/distributed.md measures both).
"""

from __future__ import annotations

import logging
import os
import selectors
import socket
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from .protocol import HANDSHAKE, QUANTITY_OF, REPLIES, Action, Codec, ProtocolError, Sizes
from .site import Site, SiteError

log = logging.getLogger("servohydraulics.serve")

_QUICKACK = getattr(socket, "TCP_QUICKACK", None)


class _Closed(Exception):
    """The client closed the connection (reason in the message)."""


class _Idle(Exception):
    """No byte from the client for ``timeout`` seconds."""


@dataclass
class ServerStats:
    """What the server did: connections by outcome (the first words of each closing reason)."""

    outcomes: Counter = field(default_factory=Counter)
    clients: int = 0
    refused: int = 0


class Server:
    """Serves ``site_factory()`` (a fresh or reset :class:`Site`) to one client at a time.

    Args:
        site: the site, reset at every connection.
        port: TCP port (0: any free one, see ``.port``).
        bind: address to listen on (default 127.0.0.1: this machine only).
        timeout: seconds a client may stay silent (handshake included) before it is dropped.
        quickack: TCP_QUICKACK after every read (False: the kernel's delayed ACK, to measure it).
        nodelay: TCP_NODELAY on the accepted sockets.
        record: a folder: each client's controller samples (a site with ``record()``, the model
            actuator) are written to ``client_NNN.csv`` there when it ends.
    """

    def __init__(self, site: Site, port: int, bind: str = "127.0.0.1", timeout: float = 60.0,
                 quickack: bool = True, nodelay: bool = True, record: str | Path | None = None):
        if not (isinstance(timeout, (int, float)) and timeout > 0):
            raise ValueError(f"invalid --timeout = {timeout!r}: seconds > 0")
        if not (isinstance(port, int) and 0 <= port <= 65535):
            raise ValueError(f"invalid --port = {port!r}: expected 0 .. 65535")
        self.site, self.timeout, self.quickack, self.nodelay = site, float(timeout), quickack, nodelay
        self.record = Path(record) if record is not None else None
        self.stats = ServerStats()
        self.actions: Counter = Counter()  # of the current (or last) client
        self._listener = socket.socket(socket.AF_INET6 if ":" in bind else socket.AF_INET, socket.SOCK_STREAM)
        self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self._listener.bind((bind, port))
        except OSError as e:
            self._listener.close()
            raise OSError(e.errno, f"cannot listen on {bind}:{port}: {e.strerror}") from None
        self._listener.listen(4)
        self._listener.setblocking(False)
        self.address = self._listener.getsockname()[:2]
        self.port = self.address[1]
        self._sel = selectors.DefaultSelector()
        self._sel.register(self._listener, selectors.EVENT_READ)
        self._client: socket.socket | None = None

    # --- the accept loop ------------------------------------------------------------------------
    def serve(self, max_clients: int | None = None, on_ready: Callable[[], None] | None = None) -> ServerStats:
        """Serves clients one after the other until ``max_clients`` have been served (None: until
        Ctrl-C, which closes everything and re-raises KeyboardInterrupt)."""
        try:  # from the first line on: a Ctrl-C right after "serving" is still logged as a stop
            log.info("serving %s actuator(s) on %s:%d (one client at a time, timeout %g s)",
                     self.site.n, *self.address, self.timeout)
            if not self._loopback():
                log.warning("listening beyond this machine (%s): whoever reaches this port drives the actuator",
                            self.address[0])
            if on_ready:
                on_ready()
            while max_clients is None or self.stats.clients < max_clients:
                self._sel.select()  # only the listener is registered here
                conn = self._accept()
                if conn is not None:
                    self._serve_client(*conn)
        except KeyboardInterrupt:
            log.info("stopped (interrupt): %s", self._summary())
            raise
        finally:
            self.close()
        log.info("done: %s", self._summary())
        return self.stats

    def _loopback(self) -> bool:
        import ipaddress

        try:
            return ipaddress.ip_address(self.address[0]).is_loopback
        except ValueError:
            return False

    def close(self) -> None:
        for s in (self._client, self._listener):
            if s is not None:
                try:
                    s.close()
                except OSError:
                    pass
        self._client = None
        self._sel.close()

    def _summary(self) -> str:
        outs = ", ".join(f"{k}: {v}" for k, v in sorted(self.stats.outcomes.items()))
        return f"{self.stats.clients} client(s), {self.stats.refused} refused; {outs or 'no connection'}"

    def _accept(self):
        try:
            sock, peer = self._listener.accept()
        except (BlockingIOError, InterruptedError):
            return None
        return sock, peer

    def _refuse(self) -> None:
        conn = self._accept()
        if conn is None:
            return
        sock, peer = conn
        self.stats.refused += 1
        log.warning("refused %s:%d: busy with another client (one at a time)", *peer[:2])
        sock.close()

    # --- one client ----------------------------------------------------------------------------
    def _serve_client(self, sock: socket.socket, peer) -> None:
        who = f"{peer[0]}:{peer[1]}"
        self.stats.clients += 1
        self._client = sock
        sock.setblocking(False)
        if self.nodelay:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._sel.register(sock, selectors.EVENT_READ)
        log.info("client %s connected", who)
        outcome = "?"
        self.actions = Counter()
        t0 = time.perf_counter()
        try:
            sizes = Sizes.from_bytes(self._recv(sock, HANDSHAKE.size))
            sizes.check(self.site.n)
            log.info("client %s: handshake control %s, acquisition %s, data_size %d", who, sizes.control,
                     sizes.daq, sizes.data_size)
            self.site.reset()
            self._session(sock, sizes)
            outcome, reason = "stopped", "the client sent stop (99)"
        except _Closed as e:
            outcome, reason = "closed", str(e)
        except _Idle as e:
            outcome, reason = "timeout", str(e)
        except ProtocolError as e:
            outcome, reason = "protocol error", str(e)
        except SiteError as e:
            outcome, reason = "site failure", str(e)
        except OSError as e:  # reset by peer, broken pipe
            outcome, reason = "connection error", f"{type(e).__name__}: {e.strerror or e}"
        except Exception as e:  # noqa: BLE001 - a bug of ours ends this client, not the server
            outcome, reason = "internal error", f"{type(e).__name__}: {e} (please report it)"
        finally:
            self._sel.unregister(sock)
            sock.close()
            self._client = None
        self.stats.outcomes[outcome] += 1
        extra = self.site.close()
        if self.record is not None and hasattr(self.site, "record"):
            from ..records import write_record

            try:
                extra["record"] = write_record(self.record / f"client_{self.stats.clients:03d}.csv",
                                               self.site.record())
            except (OSError, ValueError) as e:
                extra["record not written"] = str(e)
        level = logging.INFO if outcome == "stopped" else logging.WARNING
        actions = " ".join(f"{int(a)}x{c}" for a, c in sorted(self.actions.items()))
        log.log(level, "client %s ended (%s): %s; %d messages (action x count: %s) in %.3f s%s", who, outcome, reason,
                sum(self.actions.values()), actions or "none", time.perf_counter() - t0,
                "".join(f"; {k}: {v}" for k, v in extra.items()))

    def _session(self, sock: socket.socket, sizes: Sizes) -> None:
        site, nbytes, actions, codec = self.site, sizes.message_bytes, self.actions, Codec(sizes)
        has_time = sizes.control[4] == 1
        t_last = -np.inf
        while True:
            action, payload = codec.decode(self._recv(sock, nbytes))
            actions[action] += 1
            if action == Action.SET_TRIAL_RESPONSE:
                t = float(payload["time"][0]) if has_time else None
                if t is not None and t < t_last:
                    raise ProtocolError(f"trial time = {t:.9g} s before the previous trial's {t_last:.9g} s")
                site.set_trial(payload, t)
                if t is not None:
                    t_last = t
            elif action == Action.COMMIT_STATE:
                site.commit()
            elif action == Action.STOP:
                return
            elif action in REPLIES:
                if action == Action.GET_DAQ_RESPONSE:
                    reply = codec.daq(site.response())
                elif action in QUANTITY_OF:
                    reply = codec.reply(site.response()[QUANTITY_OF[action]])
                else:
                    reply = codec.reply(site.matrix(action))
                sock.sendall(reply)

    def _recv(self, sock: socket.socket, n: int) -> bytes:
        """Exactly n bytes from the client; other connections meanwhile are refused."""
        buf = bytearray()
        deadline = time.monotonic() + self.timeout
        while len(buf) < n:
            try:
                chunk = sock.recv(n - len(buf))
            except BlockingIOError:
                chunk = None
            if chunk is not None:
                if not chunk:
                    got = f" after {len(buf)} of {n} bytes" if buf else ""
                    raise _Closed(f"the client closed the connection{got}")
                buf += chunk
                if self.quickack and _QUICKACK is not None:
                    sock.setsockopt(socket.IPPROTO_TCP, _QUICKACK, 1)
                continue
            left = deadline - time.monotonic()
            if left <= 0:
                raise _Idle(f"no data for {self.timeout:g} s (--timeout){f', {len(buf)} of {n} bytes' if buf else ''}")
            for key, _ in self._sel.select(left):
                if key.fileobj is self._listener:
                    self._refuse()
        return bytes(buf)


def start_server_process(*args: str, env: dict[str, str] | None = None, timeout: float = 60.0,
                         prefix: Sequence[str] = ()) -> tuple[subprocess.Popen, int]:
    """Starts ``python -m servohydraulics serve --port 0 ARGS...`` in its own process (OpenSeesPy
    clients hold the GIL while they wait: a server in the client's process would never run) and
    returns it with the port it listens on.  Its log goes to a temporary file (``server_log(proc)``
    reads it; a pipe nobody drains would stall a chatty server); stop it with ``proc.terminate()``
    (SIGTERM: a clean stop), ``proc.send_signal(SIGINT)`` (Ctrl-C), or let ``--max-clients`` end it.
    ``prefix``: a command to run it under (``["ip", "netns", "exec", NAME]``)."""
    cmd = [*prefix, sys.executable, "-m", "servohydraulics", "serve", "--port", "0", *args]
    package_parent = str(Path(__file__).resolve().parents[2])  # the same servohydraulics as ours
    env = {**os.environ, **(env or {})}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (package_parent, env.get("PYTHONPATH")) if p)
    log_file = tempfile.TemporaryFile("w+")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=log_file, text=True,
                            env=env)
    proc.log_file = log_file  # type: ignore[attr-defined]
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            if sel.select(deadline - time.monotonic()):
                line = proc.stdout.readline()
                if line.startswith("listening on "):
                    return proc, int(line.rsplit(":", 1)[1])
                if not line:
                    break
    finally:
        sel.close()
    proc.kill()
    proc.wait()
    raise RuntimeError(f"serve did not start ({' '.join(cmd)}): {server_log(proc).strip()[-2000:]}")


def server_log(proc: subprocess.Popen) -> str:
    """The log so far of a server started by start_server_process."""
    f = proc.log_file  # type: ignore[attr-defined]
    f.flush()
    f.seek(0)
    return f.read()


def finish_server_process(proc: subprocess.Popen, timeout: float = 60.0, sig: int | None = None) -> str:
    """Waits for a server of start_server_process to end (after sending it ``sig``, if given;
    killed after ``timeout`` seconds), closes its pipes and returns its whole log."""
    if sig is not None and proc.poll() is None:
        proc.send_signal(sig)
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
    log = server_log(proc)
    proc.stdout.close()
    proc.log_file.close()  # type: ignore[attr-defined]
    return log
