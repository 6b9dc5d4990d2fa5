"""Seeded generator of records with hidden effects for the diagnose evaluation.

    python tests/diagnose_eval/generate.py --out build/diagnose_eval [--size default|quick] [--seed 2003]

Writes OUT/records/*.csv (time, command, displacement, force), OUT/nominal_*.toml
(the models the diagnosis is told to believe), OUT/manifest.json (record, mode,
nominal rig: what the workflow may see) and OUT/answer_key.json (what was hidden:
read only by evaluate.py, never by the workflow).

Records are made by tests/diagnose_eval/independent_plant.py, a plain-Python
RK4 simulator of Eqs (1)-(5) that shares no code with the C++ core, with effects
at graded strengths, in forms the library does not have (Stribeck and LuGre
friction, a tabulated flow curve, a delay made of a 2nd-order Bessel filter, a
continuous-time delay of the held command), none at all, or two together, and
white measurement noise on displacement and force at SNR 40, 30 and 20 dB.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import independent_plant as ip  # noqa: E402

DT = 5e-4  #: 2 kHz, the paper's DSP rate [s]
SNRS = (40, 30, 20)  #: [dB]

# A tabulated flow-spool curve with the Fig 4a shape (slope 1 at null, falling gain).
TABLE_OPENING = [0.0, 0.02, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0]
TABLE_FLOW = [0.0, 0.02, 0.047, 0.085, 0.15, 0.26, 0.40, 0.52]


def table_equivalent_b(max_opening: float) -> float:
    """The rational shape factor b closest (least squares) to the table over [0, max_opening]."""
    s = np.linspace(1e-4, max_opening, 400)
    g = np.interp(s, TABLE_OPENING, TABLE_FLOW)
    bs = np.linspace(0.0, 20.0, 20001)
    err = [np.sum((s / (1 + b * s) - g) ** 2) for b in bs]
    return float(bs[int(np.argmin(err))])


def command(mode: str, kind: str, duration: float, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """(command, x0): displacement [m], force [N] or free vibration from x0."""
    t = np.arange(int(round(duration / DT)) + 1) * DT
    ph = rng.uniform(0, 2 * np.pi, 3)
    if mode == "free":
        return np.zeros_like(t), 0.013 * (1 + 0.1 * rng.standard_normal())
    f0 = 0.5 * (1 + 0.1 * rng.standard_normal())
    chirp = np.sin(2 * np.pi * (1 + 0.8 * t) * t + ph[1])
    ramp = np.minimum(t / 0.25, 1.0)  # start from rest
    if mode == "displacement":
        big = 0.032 if kind == "std" else 0.02
        return ramp * (big * np.sin(2 * np.pi * f0 * t + ph[0]) + 0.004 * chirp), 0.0
    big = 20e3 if kind == "std" else 12e3
    return ramp * (big * np.sin(2 * np.pi * f0 * t + ph[0]) + 3e3 * chirp), 0.0


def base_truth(mode: str) -> ip.Truth:
    return ip.Truth(c=1.1e3) if mode == "free" else ip.Truth()


def nominal_rig(mode: str):
    """The model the workflow is told to believe: the calibrated preset with the
    nonlinear effects of the paper's linear analysis switched off."""
    import servohydraulics as sh

    if mode == "free":
        rig = sh.zhao2003(actuator_attached=False)
        rig.effects.coulomb_friction = False
        return rig
    rig = sh.zhao2003()
    for e in ("coulomb_friction", "spring_softening", "load_pressure", "flow_nonlinearity"):
        setattr(rig.effects, e, False)
    return rig


# effect key -> (Truth overrides at a strength value, answer name, answer parameter, modes)
def hidden(key: str, val: float, peak_spool: float) -> tuple[dict, str, dict, str]:
    """Truth overrides, the library name that should be found, the true parameter, the form."""
    if key == "coulomb":
        return {"friction": "coulomb", "F_c": val}, "coulomb_friction", {"F_c": val}, "Coulomb (tanh)"
    if key == "stribeck":
        return ({"friction": "stribeck", "F_c": val, "F_s": 1.5 * val, "v_s": 0.01}, "coulomb_friction",
                {"F_c": val}, "Stribeck, F_s = 1.5 F_c, v_s = 10 mm/s")
    if key == "lugre":
        return ({"friction": "lugre", "F_c": val, "F_s": 1.3 * val, "v_s": 0.01, "sigma_0": 5e5},
                "coulomb_friction", {"F_c": val}, "LuGre, sigma_0 = 5e5 N/m, F_s = 1.3 F_c")
    if key == "viscous":
        return {"c": val}, "viscous_damping", {"c": val}, "viscous"
    if key == "spring":
        return {"spring_softening": True, "k_2": val}, "spring_softening", {"k_2": val}, "bilinear spring"
    if key == "load_pressure":
        return {"load_pressure": True, "p_s": val}, "load_pressure", {"p_s": val}, "Eq (3) square root"
    if key == "flow":
        return {"flow": "rational", "b": val}, "flow_gain_nonlinearity", {"b": val}, "rational curve"
    if key == "flow_table":
        b_eq = table_equivalent_b(min(1.0, 2 * peak_spool))
        return ({"flow": "table", "table_opening": TABLE_OPENING, "table_flow": TABLE_FLOW},
                "flow_gain_nonlinearity", {"b": b_eq}, "tabulated curve (b: best rational fit)")
    if key == "delay":
        return {"delay": "pure", "tau": val}, "time_delay", {"tau": val}, "continuous-time delay of the ZOH command"
    if key == "delay_filter":
        return ({"delay": "filter", "tau": val}, "time_delay", {"tau": val},
                "2nd-order Bessel filter of the command (tau: its DC group delay)")
    if key == "valve":
        return {"f_v": val}, "servovalve_dynamics", {"f_v": val}, "2nd-order valve"
    if key == "leakage":
        return {"C_l": val}, "leakage", {"C_l": val}, "laminar leakage"
    if key == "piston":
        return {"m_p": val}, "piston_mass", {"m_p": val}, "rigid mass"
    if key == "spool":
        return {"x_v_max": val * peak_spool}, "spool_saturation", {"x_v_max": val * peak_spool}, "hard stop"
    raise ValueError(key)


def plan(size: str) -> list[dict]:
    """The records: single effects at graded strengths, no effect, two effects."""
    singles = [
        # (key, mode, strengths)
        ("coulomb", "displacement", [150.0, 400.0]),
        ("stribeck", "displacement", [250.0]),
        ("lugre", "displacement", [250.0]),
        ("coulomb", "free", [95.7]),
        ("stribeck", "free", [95.7]),
        ("viscous", "displacement", [5000.0, 9000.0]),
        ("viscous", "free", [2500.0]),
        ("spring", "displacement", [350.4e3]),
        ("load_pressure", "displacement", [8e6, 12e6]),
        ("flow", "displacement", [0.6, 2.0]),
        ("flow", "force", [1.0]),
        ("flow_table", "displacement", [0.0]),
        ("delay", "displacement", [0.003, 0.008]),
        ("delay_filter", "displacement", [0.006]),
        ("valve", "displacement", [30.0, 45.0]),
        ("leakage", "displacement", [1e-10, 2.5e-10]),
        ("piston", "displacement", [300.0, 600.0]),
        ("spool", "displacement", [0.6, 0.85]),
    ]
    nones = [("displacement", "std"), ("displacement", "small"), ("displacement", "std"),
             ("force", "std"), ("force", "small"), ("free", "std"), ("free", "std"), ("displacement", "small")]
    pairs = [(("coulomb", 300.0), ("flow", 1.0)), (("viscous", 6000.0), ("delay", 0.005)),
             (("spring", 350.4e3), ("load_pressure", 9e6)), (("stribeck", 250.0), ("valve", 40.0))]
    snrs = SNRS if size == "default" else (30,)
    if size == "quick":
        singles = singles[::3]
        nones = nones[:3]
        pairs = pairs[:1]
    out = []
    for snr in snrs:
        for key, mode, strengths in singles:
            for v in strengths:
                out.append({"kind": "single", "effects": [(key, v)], "mode": mode, "cmd": "std", "snr": snr})
        for mode, cmd in nones:
            out.append({"kind": "none", "effects": [], "mode": mode, "cmd": cmd, "snr": snr})
        for a, b in pairs:
            out.append({"kind": "pair", "effects": [a, b], "mode": "displacement", "cmd": "std", "snr": snr})
    return out


def generate(out: Path, size: str = "default", seed: int = 2003, duration: float = 4.0) -> None:
    import servohydraulics as sh

    out.mkdir(parents=True, exist_ok=True)
    (out / "records").mkdir(exist_ok=True)
    rng = np.random.default_rng(seed)
    for mode in ("displacement", "force", "free"):
        sh.save_rig(nominal_rig(mode), out / f"nominal_{mode}.toml")
    manifest, key = [], []
    items = plan(size)
    # the 10 s, 2 kHz runtime record
    items.append({"kind": "single", "effects": [("coulomb", 300.0)], "mode": "displacement", "cmd": "std",
                  "snr": 30, "duration": 10.0, "runtime_check": True})
    for i, it in enumerate(items):
        rid = f"r{i:03d}"
        mode = it["mode"]
        dur = it.get("duration", duration)
        u, x0 = command(mode, it["cmd"], dur, rng)
        tr = base_truth(mode)
        peak = float(np.max(np.abs(ip.simulate(tr, mode, u, DT, x0, substeps=2)["spool"]))) \
            if any(k == "spool" or k == "flow_table" for k, _ in it["effects"]) else 0.0
        answers, forms, over = [], [], {}
        for k, v in it["effects"]:
            o, name, par, form = hidden(k, v, peak)
            over.update(o)
            answers.append({"name": name, "parameters": par})
            forms.append(f"{k}: {form}")
        tr = replace(tr, **over)
        ch = ip.simulate(tr, mode, u, DT, x0)
        rec = {"time": ch["time"], "command": ch["command"]}
        for c in ("displacement", "force"):
            y = ch[c]
            rms = float(np.sqrt(np.mean(y ** 2)))
            noise = rms * 10 ** (-it["snr"] / 20) if rms > 0 and not (c == "force" and mode == "free") else 0.0
            rec[c] = y + rng.normal(0.0, noise, y.size) if noise > 0 else y.copy()
        path = out / "records" / f"{rid}.csv"
        sh.write_record(path, rec)
        manifest.append({"id": rid, "record": str(path.relative_to(out)), "mode": mode,
                         "rig": f"nominal_{mode}.toml"})
        key.append({"id": rid, "kind": it["kind"], "mode": mode, "snr": it["snr"], "answers": answers,
                    "forms": forms, "duration": dur, "runtime_check": it.get("runtime_check", False),
                    "truth": {k: v for k, v in asdict(tr).items() if not isinstance(v, list)}})
        print(f"{rid} {mode:12s} snr {it['snr']} {it['kind']:6s} {', '.join(forms) or 'none'}", flush=True)
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1))
    (out / "answer_key.json").write_text(json.dumps(key, indent=1))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default="build/diagnose_eval")
    p.add_argument("--size", choices=["default", "quick"], default="default")
    p.add_argument("--seed", type=int, default=2003)
    p.add_argument("--duration", type=float, default=4.0, help="record length [s]")
    a = p.parse_args()
    generate(Path(a.out), a.size, a.seed, a.duration)


if __name__ == "__main__":
    main()
