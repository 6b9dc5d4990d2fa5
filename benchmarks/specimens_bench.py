"""Step-time cost of the specimen and delay elements, the Pade loop delay's phase error,
and the MR damper model at Spencer et al.'s (1997) test condition.

    python benchmarks/specimens_bench.py [--steps 20000] [--repeat 5] [--write docs/specimens.md]

Times whole records through the core's run_record (``sh.simulate``: the loop over the
samples is C++, so no Python per step), divides by the steps, keeps the fastest of
--repeat passes; prints three Markdown tables and, with --write, replaces them in the
file between the markers ``<!-- specimens_bench:NAME -->`` and ``<!-- /specimens_bench -->``.
"""

from __future__ import annotations

import argparse
import math
import platform
import re
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from tqdm import tqdm

import servohydraulics as sh
from servohydraulics import _core

DT = 5e-4  # the paper's 2 kHz controller


def _cases():
    def rig(**kw):
        r = sh.zhao2003()
        for k, v in kw.items():
            if k in ("bouc_wen_hysteresis", "mr_damper", "loop_delay"):
                setattr(r.effects, k, v)
            else:
                setattr(r, k, v)
        return r
    return [
        ("paper's plant (6 states)", rig()),
        ("+ Bouc-Wen (1 state)", rig(bouc_wen_hysteresis=True)),
        ("+ MR damper (2 states)", rig(mr_damper=True)),
        ("+ loop delay, Pade 1", rig(loop_delay=True, loop_delay_order=1)),
        ("+ loop delay, Pade 3", rig(loop_delay=True, loop_delay_order=3)),
        ("+ loop delay, Pade 6", rig(loop_delay=True, loop_delay_order=6)),
        ("+ command delay 2.5 samples", rig(command_delay=2.5 * DT)),
        ("+ measurement delays 1.5 samples", rig(measurement_delay_displacement=1.5 * DT,
                                                 measurement_delay_force=1.5 * DT)),
        ("all of them (12 states)", rig(bouc_wen_hysteresis=True, mr_damper=True, loop_delay=True,
                                        loop_delay_order=3, command_delay=2.5 * DT,
                                        measurement_delay_displacement=1.5 * DT,
                                        measurement_delay_force=1.5 * DT)),
    ]


def _time(rig, command, options, repeat):
    best, res = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = sh.simulate(rig, "displacement", command, dt=DT, options=options)
        best = min(best, time.perf_counter() - t0)
    return best / len(command), res


def step_time_table(steps: int, repeat: int, progress: bool = True) -> str:
    t = np.arange(steps) * DT
    command = 0.01 * np.sin(2 * np.pi * 1.0 * t) + 0.003 * np.sin(2 * np.pi * 7.0 * t)
    methods = [("default (dopri5)", sh.solver_options()), ("CVODE", sh.solver_options("cvode")),
               ("RK4, 4 substeps", sh.solver_options("rk4", rk4_substeps=4)),
               ("RK4, automatic", sh.solver_options("rk4"))]
    rows = ["| plant | states | " + " | ".join(f"{m} [us/step] | RHS/step" for m, _ in methods) + " |",
            "|---|---|" + "---|---|" * len(methods)]
    for name, rig in tqdm(_cases(), desc="step time", disable=not progress):
        n = _core.Dynamics(rig, _core.ControlMode.Displacement).num_states
        cells = []
        for _, opt in methods:
            per_step, res = _time(rig, command, opt, repeat)
            cells.append(f"{per_step * 1e6:.2f} | {res.work.rhs_evals / len(command):.1f}")
        rows.append(f"| {name} | {n} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def pade_table(tau: float = 2e-3) -> str:
    """Phase of the (N, N) Pade approximant minus the pure delay's -w tau, in degrees (the
    magnitude is exactly 1: all-pass)."""
    freqs = [1.0, 5.0, 10.0, 20.0, 30.0]
    rows = ["| order | " + " | ".join(f"{f:g} Hz" for f in freqs) + " |", "|---|" + "---|" * len(freqs),
            "| pure delay -w tau [deg] | " + " | ".join(f"{-360 * f * tau:.3f}" for f in freqs) + " |"]
    for N in range(1, _core.MAX_PADE_ORDER + 1):
        r = sh.zhao2003()
        r.effects.loop_delay, r.loop_delay, r.loop_delay_order = True, tau, N
        P = _core.Dynamics(r, _core.ControlMode.Displacement).pade  # the core's realisation
        A = np.diag(np.ones(N - 1), 1) / tau
        A[-1, :] = -np.asarray(P["a"]) / tau
        B = np.zeros(N)
        B[-1] = 1.0 / tau
        errs = []
        for f in freqs:
            w = 2 * np.pi * f
            H = np.asarray(P["c"]) @ np.linalg.solve(1j * w * np.eye(N) - A, B) + P["d"]
            errs.append(np.degrees(np.angle(H * np.exp(1j * w * tau))))
        rows.append(f"| {N} | " + " | ".join(f"{e:.2e}" for e in errs) + " |")
    return "\n".join(rows)


def mr_table() -> str:
    """Peak force of the core's MR damper (Spencer 1997 Table 1 parameters) under the paper's
    test motion x = 1.5 cm sin(2 pi 2.5 t), over the second half of 0.8 s (steady cycles): the
    largest |F|, the signed peaks (the accumulator's k1 (x - x0) = -k1 x0 at x = 0 shifts the
    loop down) and the mean |F| where |v| is within 1e-4 of its peak."""
    X, f, T = 0.015, 2.5, 0.8
    w = 2 * np.pi * f
    rows = ["| voltage [V] | largest abs(F) [N] | signed peaks max F / min F [N] | force at peak velocity [N] |",
            "|---|---|---|---|"]
    for volts in [0.0, 0.75, 1.5, 2.25]:
        r = sh.zhao2003()
        r.effects.mr_damper, r.mr_voltage = True, volts
        dyn = _core.Dynamics(r, _core.ControlMode.Free)
        iy = dyn.layout["mr_y"]

        def state(t, s, dyn=dyn, iy=iy):
            y = np.zeros(dyn.num_states)
            y[0], y[1], y[iy], y[iy + 1] = X * np.sin(w * t), X * w * np.cos(w * t), s[0], s[1]
            return y

        t = np.arange(0, T, 1e-4)
        sol = solve_ivp(lambda t, s, dyn=dyn, iy=iy: dyn.rhs(state(t, s), 0.0)[iy:iy + 2], (0, T), [0.0, 0.0],
                        method="Radau", t_eval=t, rtol=1e-10, atol=1e-14)
        F = np.array([dyn.specimen_force(state(ti, si)) for ti, si in zip(sol.t, sol.y.T)])
        late = sol.t >= T / 2
        at_vmax = np.abs(np.cos(w * sol.t)) > 0.9999
        rows.append(f"| {volts:g} | {np.max(np.abs(F[late])):.0f} | "
                    f"+{np.max(F[late]):.0f} / {np.min(F[late]):.0f} | {np.mean(np.abs(F[late & at_vmax])):.0f} |")
    rows.append(f"\n(the accumulator's offset k1 x0 = {r.mr_k1 * r.mr_x0:.1f} N)")
    return "\n".join(rows)


def _replace(text: str, name: str, table: str) -> str:
    pat = re.compile(rf"(<!-- specimens_bench:{name} -->\n)(.*?)(<!-- /specimens_bench -->)", re.S)
    if not pat.search(text):
        raise ValueError(f"marker <!-- specimens_bench:{name} --> not found")
    return pat.sub(lambda m: m.group(1) + table + "\n" + m.group(3), text, count=1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--write", type=Path, help="Markdown file whose marked tables to replace")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--only", choices=["step_time", "pade", "mr"], help="print one table only")
    a = ap.parse_args()
    if a.only:
        print({"step_time": lambda: step_time_table(a.steps, a.repeat, not a.no_progress), "pade": pade_table,
               "mr": mr_table}[a.only]())
        return
    machine = f"{platform.machine()}, {platform.python_implementation()} {platform.python_version()}"
    step = step_time_table(a.steps, a.repeat, not a.no_progress)
    step += f"\n\n({a.steps} steps of dt = {DT * 1e3:g} ms, fastest of {a.repeat}; {machine})"
    tables = {"step_time": step, "pade": pade_table(), "mr": mr_table()}
    for name, table in tables.items():
        print(f"\n{name}\n{table}")
    if a.write:
        text = a.write.read_text()
        for name, table in tables.items():
            text = _replace(text, name, table)
        a.write.write_text(text)


if __name__ == "__main__":
    main()
