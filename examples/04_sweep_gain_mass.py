"""The paper's stability study as a sweep: the proportional gain G_p of the
displacement loop against the physically installed mass m (Zhao et al. 2003,
Fig 6b and Eq 13: a higher G_p raises the roll-off frequency, but the largest
stable G_p decays as the physical mass grows).  Runs in parallel on local processes; pass a Dask
client's executor instead (``executor=client.get_executor()``) to use a cluster.

    python3 examples/04_sweep_gain_mass.py
"""

from __future__ import annotations

import servohydraulics as sh


def main() -> None:
    df = sh.sweep(
        grid={"controller.G_p": [0.8, 2.0, 4.0], "structure.m": [700.0, 7084.0]},
        fixed={"amplitude": 0.005, "frequency": 1.0, "duration": 1.0},
        max_workers=2,
        progress=False,
    )
    df["peak_force_kN"] = df["peak_force"] / 1e3
    df["rms_error_mm"] = df["rms_tracking_error"] * 1e3
    print(df[["controller.G_p", "structure.m", "ok", "rms_error_mm", "peak_force_kN", "supply_limited"]]
          .to_string(index=False))


if __name__ == "__main__":
    main()
