"""A whole record in one call: a displacement command array in, every channel
out (NumPy), with the solver's work per sample.

The command is a stepped sine of 5 mm: 4 s at 0.5 Hz, then 4 s at 5 Hz
(whole cycles, so each segment starts and ends at zero).  Prints the
amplitude ratio of the displacement response to the command over the last
2 s of each segment: the loop tracks at 0.5 Hz and rolls off above its ~2 Hz
crossover (Eq 13), and the run's speed as a multiple of real time.

    python3 examples/03_simulate_record.py
"""

from __future__ import annotations

import time

import numpy as np

import servohydraulics as sh

FREQUENCIES = (0.5, 5.0)  # [Hz]
SEGMENT = 4.0  # [s]
AMPLITUDE = 0.005  # [m]


def main() -> dict:
    dt = 5e-4
    n = int(round(SEGMENT / dt))
    t = np.arange(n) * dt
    command = np.concatenate([AMPLITUDE * np.sin(2 * np.pi * f * t) for f in FREQUENCIES] + [[0.0]])  # [m]
    t0 = time.perf_counter()
    res = sh.simulate(sh.zhao2003(), mode="displacement", command=command, dt=dt)
    wall = time.perf_counter() - t0
    stats = {}
    for i, f in enumerate(FREQUENCIES):
        last = slice(i * n + n // 2, (i + 1) * n)
        stats[f"amplitude_ratio_{f:g}Hz"] = float(np.ptp(res.displacement[last]) / np.ptp(command[last]))
    stats["peak_force_kN"] = 1e-3 * float(np.max(np.abs(res.force)))
    stats["internal_steps_per_sample"] = float(np.mean(res.internal_steps))
    stats["realtime_factor"] = command.size * dt / wall
    for key, value in stats.items():
        print(f"{key}={value:.4f}")
    for w in res.warnings():
        print("warning:", w)
    return stats


if __name__ == "__main__":
    main()
