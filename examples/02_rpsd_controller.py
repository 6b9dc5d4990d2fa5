"""Real-time pseudodynamic testing as a laboratory runs it: the RPsD controller
wired to the rig's I/O -- read the sensors, compute the command, write the
command -- with the simulated plant standing in for the rig (the Python pair of
examples/02_rpsd_controller.cpp, same test, same numbers).

Fig 9's test: an external force ramps (half cosine) to 1.6 % of k x 1 m into the
solver of Eq (15), is held, then released.  Python does not keep the 2 kHz
deadline (the C++ example does, on CLOCK_MONOTONIC); the loop's structure is
the same.

    python3 examples/02_rpsd_controller.py [ramp_s = 2] [hold_s = 1] [free_s = 2]
"""

from __future__ import annotations

import math
import sys

import numpy as np

import servohydraulics as sh


class RigIo:
    """THE PLACE A REAL RIG'S I/O GOES.  Here the simulated plant stands in.  On a
    real rig, ``read()`` samples the ADCs into a ``sh._core.Output`` (SI units:
    displacement, velocity, acceleration, load-cell force, pressure) and
    ``write(u)`` sends the displacement command [m] to the servo controller's DAC."""

    def __init__(self, rig: sh.Rig, dt: float):
        self._plant = sh.make_plant(rig, "displacement", dt)
        self._sensors = self._plant.observe()

    def read(self):
        return self._sensors

    def write(self, command: float) -> bool:
        status, self._sensors = self._plant.step(command)
        return status.ok()


def crossing_frequency(x: np.ndarray, dt: float) -> float:
    """Frequency [Hz] from the zero crossings of x (linear interpolation)."""
    i = np.flatnonzero((x[:-1] < 0) != (x[1:] < 0))
    t = dt * (i + x[i] / (x[i] - x[i + 1]))
    return 0.5 * (t.size - 1) / (t[-1] - t[0]) if t.size > 1 else 0.0


def main(ramp: float = 2.0, hold: float = 1.0, free: float = 2.0) -> dict:
    rig = sh.zhao2003()
    tm = sh._core.ZHAO2003_TEST_METHODS  # Table I: 2 kHz, m_m, c_m, T_d, T_ld, alpha
    dt = tm.dt
    controller = sh.RpsdController(rig, restoring_force="measured_displacement")
    io = RigIo(rig, dt)
    P = 0.016 * rig.k  # [N] Fig 9: 16 mm of static displacement
    n_ramp, n_hold = round(ramp / dt), round(hold / dt)
    n = n_ramp + n_hold + round(free / dt)
    calc = np.empty(n)
    peak_command, failures = 0.0, 0
    for k in range(n):
        s = min(1.0, k / n_ramp)
        p_ext = 0.5 * P * (1.0 - math.cos(math.pi * s)) if k < n_ramp + n_hold else 0.0
        sensors = io.read()                                                # 1. read the sensors at t_k
        u = controller.command(sensors, ground_acceleration=0.0, external_force=p_ext)  # 2. compute
        failures += not io.write(u)                                        # 3. write; held until t_k+1
        calc[k] = controller.integrator_state.displacement
        peak_command = max(peak_command, abs(u))
    wn = math.sqrt(rig.k / tm.model.m_m)
    zeta = tm.model.c_m / (2 * tm.model.m_m * wn)
    stats = {"steps": n, "solver_failures": failures,
             "held_displacement_mm": 1e3 * float(np.mean(calc[n_ramp:n_ramp + n_hold])),
             "held_displacement_oracle_mm": 1e3 * P / rig.k, "peak_command_mm": 1e3 * peak_command,
             "free_frequency_Hz": crossing_frequency(calc[n_ramp + n_hold:], dt),
             "free_frequency_oracle_Hz": wn * math.sqrt(1 - zeta**2) / (2 * math.pi),
             "final_calc_displacement_mm": 1e3 * float(calc[-1])}
    for key, value in stats.items():
        print(f"{key}={value:.6f}" if isinstance(value, float) else f"{key}={value}")
    return stats


if __name__ == "__main__":
    main(*(float(a) for a in sys.argv[1:4]))
