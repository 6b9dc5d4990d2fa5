"""Network delay and jitter between OpenSees and ``servohydraulics serve`` (issue 24, item 4).

``--method netem`` (the default where the kernel has it): ``tc netem`` on the loopback device of a
private network namespace (root only; the host's own loopback is untouched and the namespace is
deleted afterwards).  ``--method relay`` (where the kernel has no sch_netem, as the machine of
docs/distributed.md): a user-space relay between client and server that holds every chunk for
the delay (plus a normal jitter, order kept) in each direction; its own TCP acknowledges at once,
so it leaves out what a delayed ACK costs the client's Nagle: a lower bound on netem's.  For each
delay the frame of servohydraulics.distributed.frame runs against the paper's actuator
(``--actuator model``, the RPsD specimen mass) for a bounded number of steps; every process runs
under a timeout.  Prints the table of docs/distributed.md and, with --plot, its figure.

    sudo PYTHONPATH=python python benchmarks/serve_netem.py [--method netem|relay] [--delays 0,1,5,20]
        [--steps 100] [--plot FILE]
"""

from __future__ import annotations

import argparse
import os
import queue
import random
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics.distributed.server import finish_server_process, start_server_process

DT = 0.01  # the frame's step [s]


def sh_run(*cmd: str) -> None:
    subprocess.run(cmd, check=True, capture_output=True, text=True, timeout=30)


def relay(listen: socket.socket, target_port: int, delay: float, jitter: float, seed: int = 0) -> None:
    """Relays one connection to 127.0.0.1:target_port, each chunk held delay + N(0, jitter) [s]
    (never reordered) in each direction; returns when both sides have closed."""
    client, _ = listen.accept()
    server = socket.create_connection(("127.0.0.1", target_port))
    for s in (client, server):
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    rng = random.Random(seed)

    def pipe(src: socket.socket, dst: socket.socket) -> None:
        q: queue.Queue = queue.Queue()

        def sender() -> None:
            while (item := q.get()) is not None:
                t, data = item
                time.sleep(max(0.0, t - time.monotonic()))
                try:
                    dst.sendall(data)
                except OSError:
                    return
            try:
                dst.shutdown(socket.SHUT_WR)
            except OSError:
                pass

        th = threading.Thread(target=sender, daemon=True)
        th.start()
        last = 0.0
        while True:
            try:
                data = src.recv(65536)
            except OSError:
                data = b""
            if not data:
                break
            src.setsockopt(socket.IPPROTO_TCP, socket.TCP_QUICKACK, 1)  # as the server does (Nagle at the client)
            last = max(last, time.monotonic() + max(0.0, delay + rng.gauss(0.0, jitter)))
            q.put((last, data))
        q.put(None)
        th.join()

    a = threading.Thread(target=pipe, args=(client, server), daemon=True)
    b = threading.Thread(target=pipe, args=(server, client), daemon=True)
    a.start()
    b.start()
    a.join(900)
    b.join(900)
    client.close()
    server.close()


def one_relay(delay_ms: float, jitter_ms: float, steps: int, rig_file: Path, folder: Path) -> dict[str, np.ndarray]:
    proc, port = start_server_process("--rig", str(rig_file), "--max-clients", "1", "--timeout", "30")
    listen = socket.create_server(("127.0.0.1", 0))
    out = folder / f"frame_{delay_ms}.npz"
    try:
        r = subprocess.Popen([sys.executable, __file__, "--relay", str(listen.getsockname()[1]), str(port),
                              str(delay_ms), str(jitter_ms)], pass_fds=(listen.fileno(),))
        subprocess.run([sys.executable, "-m", "servohydraulics.distributed.frame", "--port",
                        str(listen.getsockname()[1]), "--dt", str(DT), "--duration", str(steps * DT),
                        "--out", str(out)],
                       check=True, capture_output=True, text=True, timeout=900,
                       env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
        r.wait(timeout=60)
    finally:
        listen.close()
        finish_server_process(proc, timeout=60)
    return dict(np.load(out))


def one(delay_ms: float, jitter_ms: float, steps: int, rig_file: Path, folder: Path) -> dict[str, np.ndarray]:
    ns = f"shnetem{os.getpid()}"
    sh_run("ip", "netns", "add", ns)
    try:
        sh_run("ip", "netns", "exec", ns, "ip", "link", "set", "lo", "up")
        if delay_ms > 0:
            jitter = [f"{jitter_ms}ms", "distribution", "normal"] if jitter_ms > 0 else []
            sh_run("ip", "netns", "exec", ns, "tc", "qdisc", "add", "dev", "lo", "root", "netem", "delay",
                   f"{delay_ms}ms", *jitter)
        # a stopwatch on everything: the server ends after one client or 30 s of silence, the client after 15 min
        proc, port = start_server_process("--rig", str(rig_file), "--max-clients", "1", "--timeout", "30",
                                          prefix=["ip", "netns", "exec", ns, "timeout", "900"])
        out = folder / f"frame_{delay_ms}.npz"
        try:
            subprocess.run(["ip", "netns", "exec", ns, "timeout", "900", sys.executable, "-m",
                            "servohydraulics.distributed.frame", "--port", str(port), "--dt", str(DT),
                            "--duration", str(steps * DT), "--out", str(out)],
                           check=True, capture_output=True, text=True, timeout=960,
                           env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
        finally:
            finish_server_process(proc, timeout=60)
        return dict(np.load(out))
    finally:
        sh_run("ip", "netns", "del", ns)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--delays", default="0,1,5,20", help="one-way netem delays on lo [ms] (default 0,1,5,20)")
    p.add_argument("--jitter", type=float, default=0.1, help="netem jitter as a fraction of the delay (default 0.1)")
    p.add_argument("--steps", type=int, default=100, help="frame steps of 10 ms per run (default 100)")
    p.add_argument("--plot", default=None, help="figure to write")
    p.add_argument("--method", choices=["netem", "relay"], default="netem")
    p.add_argument("--relay", nargs=4, metavar=("LISTEN_FD_PORT", "TARGET", "DELAY_MS", "JITTER_MS"),
                   help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.relay:  # the relay process of --method relay: the listening socket is inherited
        fd_port, target, d, j = a.relay
        listen = next(socket.socket(fileno=fd) for fd in range(3, 256) if _is_listener(fd, int(fd_port)))
        relay(listen, int(target), float(d) / 1e3, float(j) / 1e3)
        return 0
    if a.method == "netem" and os.geteuid() != 0:
        print("serve_netem: netem needs root (ip netns, tc); nothing run", file=sys.stderr)
        return 2
    delays = [float(d) for d in a.delays.split(",")]
    rig = sh.zhao2003()
    rig.m = 140.0
    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        rig_file = sh.save_rig(rig, folder / "rig.toml")
        for d in delays:
            runs[d] = (one if a.method == "netem" else one_relay)(d, a.jitter * d, a.steps, rig_file, folder)
    ref = runs[delays[0]]["displacement"]
    print(f"| {a.method} delay (jitter) per direction [ms] | steps | wall time per step, median [ms] | p99 [ms] | "
          f"max abs first-floor difference to {delays[0]:g} ms [m] |")
    print("|---|---|---|---|---|")
    for d, r in runs.items():
        s = r["step_seconds"][1:]
        print(f"| {d:g} ({a.jitter * d:.2g}) | {len(s)} | {1e3 * np.median(s):.3f} | "
              f"{1e3 * np.percentile(s, 99):.3f} | {np.abs(r['displacement'] - ref).max():.3g} |")
    if a.plot:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(8, 5.5), layout="constrained")
        ax1, ax2 = fig.subplots(2, 1)
        for d, r in runs.items():
            ax1.plot(r["time"], 1e3 * r["displacement"][:, 0], lw=1, label=f"{d:g} ms")
            ax2.semilogy(np.arange(1, len(r["step_seconds"])), 1e3 * r["step_seconds"][1:], ".", ms=3,
                         label=f"{d:g} ms")
        ax1.set_xlabel("simulated time [s]")
        ax1.set_ylabel("first floor [mm]")
        how = "tc netem on lo" if a.method == "netem" else "a delaying relay"
        ax1.set_title(f"frame response vs one-way delay ({how}): the curves coincide, the protocol is time-stamped",
                      fontsize=9)
        ax1.legend(fontsize=8, title="one-way delay")
        ax2.set_xlabel("step")
        ax2.set_ylabel("wall time per step [ms]")
        fig.savefig(a.plot, dpi=110)
        print(f"wrote {a.plot}")
    return 0


def _is_listener(fd: int, port: int) -> bool:
    try:
        s = socket.socket(fileno=os.dup(fd))
    except OSError:
        return False
    try:
        return s.type == socket.SOCK_STREAM and s.getsockname()[1:2] == (port,)
    except OSError:
        return False
    finally:
        s.close()


if __name__ == "__main__":
    raise SystemExit(main())
