"""What a network delay would do to the frame in a real-time distributed test (issue 24, item 4).

The protocol is time-stamped, so a network delay does not change a test whose site follows the
client's time channel (benchmarks/serve_netem.py: to the bit).  In a real-time test the site
runs on the wall clock and the delay enters the loop: the trial reaches the actuator d late and
the force reaches the client d late.  This emulates that with the rig's own delay elements:
``delays.command_delay = d`` (the held command switches d late) and
``delays.measurement_delay_force = d`` (the load cell is read d late).  It then runs the frame of
servohydraulics.distributed.frame through ``servohydraulics serve`` (the paper's actuator, RPsD
specimen mass, with and without the T_d lead).  It prints the table of docs/distributed.md
and, with --plot, its figure.

    PYTHONPATH=python python benchmarks/serve_delay_effect.py [--delays 0,1,5,20] [--plot FILE]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics.distributed.frame import run_frame, run_frame_served

DT, DURATION = 0.005, 4.0


def run(rig: sh.Rig, controller: str, folder: Path) -> np.ndarray:
    path = sh.save_rig(rig, folder / "rig.toml")
    res = run_frame_served("--rig", str(path), "--controller", controller, dt=DT, duration=DURATION)
    return res["displacement"][:, 0]


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--delays", default="0,1,5,20", help="one-way delays [ms] (default 0,1,5,20; at most 32)")
    p.add_argument("--plot", default=None, help="figure to write")
    a = p.parse_args()
    delays = [float(d) for d in a.delays.split(",")]
    base = sh.zhao2003()
    base.m = 140.0
    ideal = run_frame(local_k=base.k, dt=DT, duration=DURATION)
    t, x0 = ideal["time"], ideal["displacement"][:, 0]
    out: dict[tuple[str, float], np.ndarray] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for controller in ("none", "lead"):
            for d in delays:
                rig = sh.copy_rig(base)
                rig.command_delay = rig.measurement_delay_force = d / 1e3
                out[(controller, d)] = run(rig, controller, Path(tmp))
    print(f"| one-way delay [ms] | first floor peak, actuator as it is [mm] | NRMS vs ideal brace [%] | "
          f"peak, with the T_d lead [mm] | NRMS vs ideal [%] |  (ideal brace: peak {1e3 * np.abs(x0).max():.2f} mm)")
    print("|---|---|---|---|---|")
    for d in delays:
        cells = []
        for c in ("none", "lead"):
            x = out[(c, d)]
            cells += [f"{1e3 * np.abs(x).max():.2f}", f"{100 * np.sqrt(np.mean((x - x0) ** 2) / np.mean(x0 ** 2)):.1f}"]
        print(f"| {d:g} | " + " | ".join(cells) + " |")
    if a.plot:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(8, 5.5), layout="constrained")
        axes = fig.subplots(2, 1, sharex=True)
        for ax, c, title in zip(axes, ("none", "lead"), ("the paper's actuator", "with the T_d = 68 ms lead")):
            ax.plot(t, 1e3 * x0, "k", lw=1.5, label="ideal brace")
            for d in delays:
                ax.plot(t, 1e3 * out[(c, d)], lw=1, label=f"{d:g} ms")
            ax.set_ylabel("first floor [mm]")
            ax.set_title(f"{title}: one-way network delay in a real-time test (emulated)", fontsize=9)
            ax.legend(fontsize=7, ncol=3)
        axes[1].set_xlabel("time [s]")
        fig.savefig(a.plot, dpi=110)
        print(f"wrote {a.plot}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
