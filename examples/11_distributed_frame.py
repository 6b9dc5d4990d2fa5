"""A virtual lab before the real one: an OpenSees frame (OpenSeesPy's genericClient element)
drives the paper's actuator served by ``servohydraulics serve`` in another process, and its
response is compared with the same frame whose brace is an ideal local spring.

The frame is servohydraulics.distributed.frame (two storeys, the brace at the first floor, a
2 Hz ground motion); the specimen is the rig's structure with the RPsD specimen mass (140 kg).
Three runs: the local spring (what the analyst expects), the remote actuator as it is, and the
remote actuator with the paper's amplitude compensation T_d = 68 ms (--controller lead).

    python3 examples/11_distributed_frame.py [DURATION_S] [--plot FILE.png]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics.distributed.frame import run_frame, run_frame_served
from servohydraulics.distributed.site import tracking_delay

DT = 0.005  # the frame's step [s]: 10 controller samples of 0.5 ms


def remote(rig_file: Path, duration: float, controller: str, folder: Path):
    res = run_frame_served("--rig", str(rig_file), "--controller", controller, "--record", str(folder / controller),
                           dt=DT, duration=duration)
    return res, sh.read_record(folder / controller / "client_001.csv")


def main(duration: float = 4.0, plot: str | None = None) -> None:
    rig = sh.zhao2003()
    rig.m = 140.0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        rig_file = sh.save_rig(rig, folder / "rig.toml")
        ideal = run_frame(local_k=rig.k, dt=DT, duration=duration)
        runs = {name: remote(rig_file, duration, name, folder) for name in ("none", "lead")}
    x0 = ideal["displacement"][:, 0]
    print(f"ideal_peak_mm={1e3 * np.abs(x0).max():.3f}")
    for name, (res, rec) in runs.items():
        x = res["displacement"][:, 0]
        nrms = np.sqrt(np.mean((x - x0) ** 2) / np.mean(x0 ** 2))
        track = np.sqrt(np.mean((rec.displacement - rec.command) ** 2) / np.mean(rec.command ** 2))
        print(f"{name}_peak_mm={1e3 * np.abs(x).max():.3f} {name}_vs_ideal_pct={100 * nrms:.1f} "
              f"{name}_tracking_error_pct={100 * track:.1f} "
              f"{name}_delay_ms={1e3 * tracking_delay(rec.time, rec.command, rec.displacement):.1f}")
    if plot:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(8, 6), layout="constrained")
        ax1, ax2 = fig.subplots(2, 1, sharex=True)
        ax1.plot(ideal["time"], 1e3 * x0, "k", lw=1.5, label="ideal brace (local spring)")
        labels = {"none": "paper's actuator (serve)", "lead": "paper's actuator + T_d lead (serve --controller lead)"}
        for name, (res, _) in runs.items():
            ax1.plot(res["time"], 1e3 * res["displacement"][:, 0], lw=1, label=labels[name])
        ax1.set_ylabel("first floor [mm]")
        ax1.legend(fontsize=8)
        ax1.set_title("OpenSees frame, brace served by servohydraulics serve (genericClient)")
        rec = runs["none"][1]
        ax2.plot(rec.time, 1e3 * rec.command, "k", lw=1, label="trial displacement (command)")
        ax2.plot(rec.time, 1e3 * rec.displacement, lw=1, label="measured (paper's actuator)")
        ax2.set_xlabel("time [s]")
        ax2.set_ylabel("actuator [mm]")
        ax2.legend(fontsize=8)
        fig.savefig(plot, dpi=110)
        print(f"wrote {plot}")


if __name__ == "__main__":
    args = sys.argv[1:]
    out = None
    if "--plot" in args:
        i = args.index("--plot")
        out = args[i + 1]
        del args[i:i + 2]
    main(float(args[0]) if args else 4.0, out)
