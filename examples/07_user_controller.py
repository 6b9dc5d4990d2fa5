"""Your own tracking controller in the RTHS benchmark, in pure Python: the
benchmark's PI + phase lead (Silva et al. 2020, Sec 5.2-5.3) written out as a
user would write it, run by the C++ loop, and compared with the built-in C++
sample controller it re-implements (the same J; the commands agree to round-off).

The interface (docs/rths-benchmark.md, "Bring your own controller"): a class with

    reset() -> None
    command(desired, desired_velocity, desired_acceleration, measured, measured_force) -> float

called once per 1/4096 s sample with the numerical substructure's desired interface
displacement [m], velocity [m/s] and acceleration [m/s^2] and the measured specimen
displacement [m] and force [N]; it returns the actuator command [m], held until the
next sample.  From the command line:

    PYTHONPATH=examples servohydraulics rths-benchmark --controller 07_user_controller:PiLead ...

``Delegating`` below wraps a built-in: the published case-1 row, bit for bit.
examples/07_user_controller.cpp is the same controller in C++, for when Python is too slow.

    python3 examples/07_user_controller.py [DATA]   # DATA: the benchmark files (case 1, El Centro x 0.4);
                                                     # none: the embedded case 1, synthetic ground motion
"""

from __future__ import annotations

import sys
import time

import numpy as np

from servohydraulics import rths

AD, DA = rths.core.Converter.Kind.AnalogToDigital, rths.core.Converter.Kind.DigitalToAnalog


def tustin(b1: float, b0: float, a1: float, a0: float, h: float) -> tuple[float, float, float]:
    """(n0, n1, d1) of (b1 s + b0) / (a1 s + a0) by Tustin at h: y_k = -d1 y_k-1 + n0 u_k + n1 u_k-1."""
    c = 2.0 / h
    D = a1 * c + a0
    return (b1 * c + b0) / D, (b0 - b1 * c) / D, (a0 - a1 * c) / D


class PiLead:
    """PI + phase lead in pure Python (the benchmark's sample controller, re-implemented)."""

    def __init__(self, dt: float = rths.DT, Kp: float = 2.0, Ki: float = 95.0,
                 lead: tuple[float, float, float] = (50.83163360273612, 8570.397339444286, 8570.397339444286)):
        self.lead = tustin(lead[0], lead[1], 1.0, lead[2], dt)  # G_T(s) = (b1 s + b0) / (s + a0), Eq 24
        self.pi = tustin(Kp, Ki, 1.0, 0.0, dt)                   # G_C(s) = Kp + Ki / s, Eq 23
        self.ad = rths.core.benchmark_converter(AD)  # the benchmark's 18-bit converters, from the core
        self.da = rths.core.benchmark_converter(DA)
        self.reset()

    def reset(self) -> None:
        self.r1 = self.yl1 = self.e1 = self.yc1 = 0.0

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force) -> float:
        n0, n1, d1 = self.lead
        r = self.ad(desired)
        yl = -d1 * self.yl1 + n0 * r + n1 * self.r1  # phase lead on the reference
        self.r1, self.yl1 = r, yl
        e = self.ad(self.da(yl) - measured)           # tracking error
        n0, n1, d1 = self.pi
        yc = -d1 * self.yc1 + n0 * e + n1 * self.e1  # PI
        self.e1, self.yc1 = e, yc
        return self.da(yc)


class Delegating:
    """Delegates to a built-in controller (wrap or extend one: rths.make_controller returns it)."""

    def __init__(self, name: str = "sample"):
        self.inner = rths.make_controller(name)

    def reset(self) -> None:
        self.inner.reset()

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force) -> float:
        return self.inner.command(desired, desired_velocity, desired_acceleration, measured, measured_force)


def main(data: str | None = None) -> None:
    if data:
        case, rec = rths.load_case(data, 1), rths.load_record(data, "elcentro")
    else:
        case, rec = rths.embedded_case(1), rths.synthetic_record(duration=20.0)
    ref = rths.case_reference(case, rec)
    runs = {}
    for name, ctrl in (("builtin", "sample"), ("python", PiLead())):
        t0 = time.perf_counter()
        runs[name] = rths.run_trial(case, rec, ctrl, reference=ref, keep_signals=True)
        runs[name].wall_time = time.perf_counter() - t0
    b, p = runs["builtin"], runs["python"]
    diff = float(np.max(np.abs(b.signals["command"] - p.signals["command"])))
    print(f"record={rec.name} synthetic={rec.synthetic} samples={rec.samples()}")
    for name, t in runs.items():
        print(f"{name}_ok={int(t.ok)}\n{name}_wall_s={t.wall_time:.3f}")
        print("\n".join(f"{name}_{k}={v:.2f}" for k, v in t.criteria.items()))
    print(f"max_command_difference_m={diff:.3e}\nsame_J={int(b.J == p.J)}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
