"""The benchmark's input: a synthetic ground-motion record and the displacement
command it gives in real-time pseudodynamic testing.

The ground acceleration is Kanai-Tajimi filtered white noise (firm soil,
omega_g = 5 pi rad/s, zeta_g = 0.6) under a Jennings-Housner-Tsai envelope
(2 s rise, 10 s strong motion, exponential decay), seeded, scaled to a peak
ground acceleration.  The displacement command is the response of the rig's
linear SDOF (m, c, k of the rig, Table I) to that record: what an RPsD
controller would send to the actuator.  Exact ZOH discretisation at the
controller rate (scipy.signal.cont2discrete).
"""

from __future__ import annotations

import numpy as np
from scipy import signal

G = 9.80665  # [m/s^2]


def ground_acceleration(duration: float = 60.0, dt: float = 5e-4, pga: float = 0.3 * G,
                        seed: int = 2003) -> np.ndarray:
    """Synthetic ground acceleration [m/s^2], ``round(duration/dt) + 1`` samples."""
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    rng = np.random.default_rng(seed)
    w = rng.standard_normal(n) / np.sqrt(dt)  # unit-intensity white noise
    wg, zg = 5.0 * np.pi, 0.6
    # Kanai-Tajimi: H(s) = (2 zg wg s + wg^2) / (s^2 + 2 zg wg s + wg^2)
    sysd = signal.cont2discrete(([2 * zg * wg, wg * wg], [1.0, 2 * zg * wg, wg * wg]), dt, method="bilinear")
    a = signal.lfilter(np.ravel(sysd[0]), np.ravel(sysd[1]), w)
    env = np.where(t < 2.0, (t / 2.0) ** 2, np.where(t < 12.0, 1.0, np.exp(-0.25 * (t - 12.0))))
    a = a * env
    return a * (pga / np.max(np.abs(a)))


def sdof_displacement(ag: np.ndarray, dt: float, m: float, c: float, k: float) -> np.ndarray:
    """Relative displacement [m] of m x'' + c x' + k x = -m a_g (ZOH-exact)."""
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    B = np.array([[0.0], [-1.0]])
    Ad, Bd, *_ = signal.cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), dt, method="zoh")
    x = np.zeros((ag.size, 2))
    for i in range(1, ag.size):  # 120 000 tiny 2x2 steps: ~0.3 s, once per benchmark
        x[i] = Ad @ x[i - 1] + Bd[:, 0] * ag[i - 1]
    return x[:, 0]


def displacement_command(rig, duration: float = 60.0, dt: float = 5e-4, pga: float = 0.3 * G,
                         seed: int = 2003, damping_ratio: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """(ground acceleration [m/s^2], displacement command [m]) for the rig's SDOF
    (mass m, stiffness k of the rig, ``damping_ratio`` of critical)."""
    ag = ground_acceleration(duration, dt, pga, seed)
    c = 2.0 * damping_ratio * np.sqrt(rig.k * rig.m)
    return ag, sdof_displacement(ag, dt, rig.m, c, rig.k)


def write_command_csv(path, command: np.ndarray, ground_accel: np.ndarray, dt: float) -> None:
    """The C++ benchmark's input: header, then ``time,command,ground_accel`` rows
    (displacement command [m], ground acceleration [m/s^2])."""
    t = np.arange(command.size) * dt
    np.savetxt(path, np.column_stack([t, command, ground_accel]), delimiter=",", header="time,command,ground_accel",
               comments="", fmt="%.17g")


def main(argv=None) -> int:
    """Writes the benchmark's command record (the preset rig, seed 2003) for sh_bench_step_time:

        python3 benchmarks/ground_motion.py --out command.csv
    """
    import argparse
    import sys
    from pathlib import Path

    ap = argparse.ArgumentParser(description=main.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="the CSV to write")
    ap.add_argument("--duration", type=float, default=60.0, help="record length [s]")
    ap.add_argument("--dt", type=float, default=5e-4, help="controller sample [s]")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
    import servohydraulics as sh

    ag, u = displacement_command(sh.zhao2003(), duration=args.duration, dt=args.dt)
    write_command_csv(args.out, u, ag, args.dt)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
