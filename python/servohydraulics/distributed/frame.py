"""A two-storey OpenSees frame whose first-floor brace is the specimen: remote (OpenSees'
``genericClient`` element to a site server) or the equivalent local spring.  The tests, the
example (examples/11_distributed_frame.py) and the benchmark (benchmarks/serve_latency.py)
run it in their own process: OpenSeesPy holds the GIL while it waits on the network, so the
server must live in another process.

    python -m servohydraulics.distributed.frame --port 8090 --out remote.npz
    python -m servohydraulics.distributed.frame --local-k 700800 --out local.npz
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Sequence

import numpy as np

#: The frame: bay width, storey height [m], columns and beams (E [Pa], A [m^2], I [m^4]), floor mass per node [kg].
BAY, STOREY = 6.0, 3.5
E, A_COL, I_COL, A_BEAM, I_BEAM = 200e9, 1.0e-2, 4.0e-5, 1.0e-2, 2.0e-4
FLOOR_MASS = 3000.0
#: The ground motion: a_g(t) = PGA sin(2 pi f t) sin(pi t / T)^2 over T [m/s^2].
PGA, FREQUENCY, DURATION = 1.0, 2.0, 4.0
SPECIMEN_NODE, SPECIMEN_TAG = 3, 100


def linear_specimen_rig(k: float = 700800.0):
    """The preset with a linear spring of stiffness k [N/m] as its specimen: friction, softening
    and the piston mass off, damping 0 and a negligible mass (1e-300 kg), so that ``serve
    --actuator ideal`` answers exactly k x and the frame's local twin is a zeroLength spring of k."""
    from ..rig import zhao2003

    rig = zhao2003()
    rig.m, rig.c, rig.k = 1e-300, 0.0, float(k)
    rig.effects.coulomb_friction = rig.effects.spring_softening = rig.effects.piston_mass = False
    return rig


def ground_acceleration(dt: float, duration: float = DURATION, pga: float = PGA, frequency: float = FREQUENCY):
    t = np.arange(int(round(duration / dt)) + 1) * dt
    return t, pga * np.sin(2 * math.pi * frequency * t) * np.sin(math.pi * t / duration) ** 2


def build(ops, port: int | None, host: str, local_k: float | None) -> None:
    """The model: nodes 1, 2 on the ground, 3, 4 the first floor, 5, 6 the second; the
    specimen acts horizontally on node 3 against the ground."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in ((1, 0, 0), (2, BAY, 0), (3, 0, STOREY), (4, BAY, STOREY), (5, 0, 2 * STOREY),
                      (6, BAY, 2 * STOREY)):
        ops.node(tag, float(x), float(y))
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 1, 1, 1)
    for tag in (3, 4, 5, 6):
        ops.mass(tag, FLOOR_MASS, FLOOR_MASS, 0.0)
    ops.geomTransf("Linear", 1)
    for tag, (i, j) in enumerate(((1, 3), (2, 4), (3, 5), (4, 6)), start=1):
        ops.element("elasticBeamColumn", tag, i, j, A_COL, E, I_COL, 1)
    for tag, (i, j) in enumerate(((3, 4), (5, 6)), start=5):
        ops.element("elasticBeamColumn", tag, i, j, A_BEAM, E, I_BEAM, 1)
    if port is not None:
        ops.element("genericClient", SPECIMEN_TAG, "-node", SPECIMEN_NODE, "-dof", 1, "-server", int(port), host)
    elif local_k is not None:
        ops.node(7, 0.0, STOREY)
        ops.fix(7, 1, 1, 1)
        ops.uniaxialMaterial("Elastic", 1, float(local_k))
        ops.element("zeroLength", SPECIMEN_TAG, 7, SPECIMEN_NODE, "-mat", 1, "-dir", 1)
    ops.rayleigh(0.3, 0.0, 0.0, 0.0)  # mass-proportional only: the same damping with either specimen


def run_frame(port: int | None = None, host: str = "127.0.0.1", local_k: float | None = None, dt: float = 0.01,
              duration: float = DURATION, pga: float = PGA, algorithm: str = "Linear") -> dict[str, np.ndarray]:
    """Runs the frame under the ground motion (Newmark average acceleration, ``algorithm``
    ``"Linear"``: one solve a step, as a hybrid test runs; or ``"Newton"``).  Returns the
    time, the floor displacements (node 3 and 5, horizontal) [m], the specimen's force [N]
    and each step's wall time [s]."""
    import openseespy.opensees as ops

    build(ops, port, host, local_k)
    t, ag = ground_acceleration(dt, duration, pga)
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *ag.tolist())
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 20)
    ops.algorithm(algorithm)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    n = len(t)
    disp, force, wall = np.zeros((n, 2)), np.zeros(n), np.zeros(n)
    for k in range(1, n):
        t0 = time.perf_counter()
        if ops.analyze(1, dt) != 0:
            raise RuntimeError(f"OpenSees analyze failed at t = {t[k]:.4g} s")
        wall[k] = time.perf_counter() - t0
        disp[k] = ops.nodeDisp(3, 1), ops.nodeDisp(5, 1)
        force[k] = ops.eleResponse(SPECIMEN_TAG, "forces")[0] if port is not None else ops.eleResponse(
            SPECIMEN_TAG, "basicForce")[0]
    ops.wipe()  # a genericClient sends stop (99)
    return {"time": t, "displacement": disp, "force": force, "step_seconds": wall}


def run_frame_served(*server_args: str, dt: float = 0.01, duration: float = DURATION, pga: float = PGA,
                     algorithm: str = "Linear") -> dict[str, np.ndarray]:
    """``servohydraulics serve SERVER_ARGS... --max-clients 1`` in its own process, the frame
    against it (run_frame), the server's log under ``"log"``; RuntimeError unless the server
    ended the client cleanly."""
    from .server import finish_server_process, start_server_process

    proc, port = start_server_process(*server_args, "--max-clients", "1")
    try:
        res = run_frame(port=port, dt=dt, duration=duration, pga=pga, algorithm=algorithm)
    finally:
        log = finish_server_process(proc)
    if "ended (stopped)" not in log:
        raise RuntimeError(f"the server did not end the client cleanly:\n{log}")
    return {**res, "log": log}


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--port", type=int, default=None, help="the site server's port (the specimen is remote)")
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--local-k", type=float, default=None, help="no server: a local spring of this stiffness [N/m]")
    p.add_argument("--dt", type=float, default=0.01)
    p.add_argument("--duration", type=float, default=DURATION)
    p.add_argument("--pga", type=float, default=PGA)
    p.add_argument("--algorithm", default="Linear", choices=["Linear", "Newton"])
    p.add_argument("--out", required=True, help=".npz to write")
    a = p.parse_args(argv)
    res = run_frame(a.port, a.host, a.local_k, a.dt, a.duration, a.pga, a.algorithm)
    np.savez(a.out, **res)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
