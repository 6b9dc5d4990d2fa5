"""Step the plant one controller sample at a time, as a controller would
(the Python pair of examples/01_plant_step.cpp, same rig, same command).

A 10 mm, 1 Hz sine displacement command at 2 kHz for ``duration`` seconds.
Python does not keep a 2 kHz deadline (no clock_nanosleep loop here): this
measures the cost of one ``Plant.step`` call through the binding.

    python3 examples/01_plant_step.py [duration_s = 2]
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

import servohydraulics as sh


def main(duration: float = 2.0, amplitude: float = 0.01, frequency: float = 1.0) -> dict:
    dt = 5e-4  # [s] 2 kHz
    n = int(round(duration / dt))
    plant = sh.make_plant(sh.zhao2003(), "displacement", dt)
    step_us = np.empty(n)
    peak_x = peak_f = 0.0
    for k in range(n):
        command = amplitude * math.sin(2 * math.pi * frequency * k * dt)  # [m]
        t0 = time.perf_counter()
        status, out = plant.step(command)
        step_us[k] = 1e6 * (time.perf_counter() - t0)
        if not status.ok():
            raise RuntimeError(f"step {k}: {status.message}")
        peak_x = max(peak_x, abs(out.displacement))
        peak_f = max(peak_f, abs(out.force))
    stats = {"steps": n, "step_us_median": float(np.median(step_us)), "step_us_max": float(step_us.max()),
             "simulated_time_s": plant.time, "peak_displacement_mm": 1e3 * peak_x, "peak_force_kN": 1e-3 * peak_f}
    for key, value in stats.items():
        print(f"{key}={value:.4f}" if isinstance(value, float) else f"{key}={value}")
    return stats


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 2.0)
