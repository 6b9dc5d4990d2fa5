"""Seeded generator of records with hidden effects for the diagnose evaluation.

    python evaluation/diagnose_eval/generate.py --out build/diagnose_eval [--size default|quick] [--seed 2003]
        [--jobs 2] [--cases all|new|old]

Writes OUT/records/*.csv (time, command, displacement, force), OUT/nominal_*.toml
(the models the diagnosis is told to believe), OUT/manifest.json (record, mode,
nominal rig: what the workflow may see) and OUT/answer_key.json (what was hidden:
read only by evaluate.py, never by the workflow).

Records are made by evaluation/diagnose_eval/independent_plant.py, a plain-Python
RK4 simulator of Eqs (1)-(5) that shares no code with the C++ core, with effects
at graded strengths, in forms the library does not have (Stribeck and LuGre
friction, a tabulated flow curve, a delay made of a 2nd-order Bessel filter, a
continuous-time delay of the held command), none at all, or two together, and
white measurement noise on displacement and force at SNR 40, 30 and 20 dB.
Records are made in parallel (``--jobs`` processes), each with its own seeded
random stream (seed, record number), so the set does not depend on ``--jobs``.

Truth of each answer (decided from the physics, before any diagnosis):
in-library forms: the simulator's own parameter.  Stribeck friction: the
energy-equivalent Coulomb force F_eq = sum(F_fr v) / sum(|v|) over the record
(the Coulomb level that dissipates the same energy over the record's motion,
which is what a Coulomb model fitted to the record can be asked to find); the
sliding Coulomb level F_c is kept as a second truth (``alt``).  LuGre friction
(with a Stribeck peak F_s = 1.3 F_c the library's LuGre does not have): the name
``lugre_friction``, its bristle stiffness sigma_0 and sliding level F_c.  Flow
curves: the full-opening flow ratio g(1) = Q(x_v = 1) / K_v (rational curve:
1 / (1 + b)); the tabulated curve bending from 2 % opening is run with a force
sweep that opens the spool to about 7 % only, so its truth is g at the record's
peak opening (g(1), outside the record, kept as ``alt``); the preset-kind table
is run with a large sweep (peak opening beyond 0.3) so that g(1) is within reach.
Filter delay: the Bessel filter's DC group delay (named command_delay: a filter
before the loop).  In-loop delay: a true transport delay of the valve drive
(the library's loop_delay is a Pade approximant of it): its delay.  Bouc-Wen
specimen (n = 1, beta = gamma, the library's form): its yield displacement
x_y = A / (beta + gamma) and yield force F_y = bw_k x_y.

Other rigs (``RIGS``): "paper" (Zhao et al. 2003, the default), "rigB" (another
mass, stiffness, piston area, valve, oil column and loop gain), "rigC" (a
light, soft, fast rig: a damper frame) and "rigD" (a small rig: 150 kg, 6 cm^2,
a 50 Hz valve, where a piston of tens of kg is a large share of the moving
mass).  The nominal rig the workflow is told to believe for each is written
as OUT/nominal_<rig>_<mode>.toml (the paper's as OUT/nominal_<mode>.toml).

``--cases new`` keeps only the cases added for issue 13 (in-loop and command
delays, load pressure + 400 N Coulomb, Bouc-Wen specimens, the other rigs in
displacement and force control, their no-effect records); ``--cases issue25``
only those added for issue 25, of the kinds of the two blind misses at other
magnitudes, rigs and seeds (``plan_issue25``: heavy pistons on small rigs, behind
the load cell and seen by it, the load-pressure term with a second effect on
records of large forces and low noise).
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

# A tabulated flow-spool curve with the Fig 4a shape (slope 1 at null, falling gain from 2 % opening).
TABLE_OPENING = [0.0, 0.02, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0]
TABLE_FLOW = [0.0, 0.02, 0.047, 0.085, 0.15, 0.26, 0.40, 0.52]
# A curve of the preset's kind: linear below 10 % opening, g(1) = 0.56 (values typed from
# docs/calibration.md "Flow curve"; the simulator interpolates them itself)
KNEE_OPENING = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0]
KNEE_FLOW = [0.0, 0.1, 0.19, 0.265, 0.33, 0.385, 0.47, 0.56]


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
    if kind in ("sweep", "bigsweep"):  # a force sweep 0.5-3.5 Hz through f_n
        # 15 kN opens the spool to about 0.07; 75 kN to about 0.35 (beyond a 10 % knee, like Fig 4b's 0.32)
        sweep = np.sin(2 * np.pi * (0.5 * t + 0.5 * 3.0 / duration * t ** 2) + ph[0])
        return ramp * (75e3 if kind == "bigsweep" else 15e3) * sweep, 0.0
    big = 20e3 if kind == "std" else 12e3
    return ramp * (big * np.sin(2 * np.pi * f0 * t + ph[0]) + 3e3 * chirp), 0.0


#: rigs other than the paper's: the Truth fields that differ (the same names as the rig keys), and the scale of
#: their commands against the paper rig's (displacement, force)
RIGS = {
    "paper": ({}, 1.0, 1.0),
    # a lighter, softer structure on a smaller piston, a slower under-damped valve and a higher loop gain
    "rigB": ({"m": 2500.0, "c": 800.0, "k": 250e3, "k_2": 125e3, "m_p": 30.0, "A": 50e-4, "K_a": 0.8e-12,
              "C_l": 2e-11, "K_v": 1.0e-2, "f_v": 40.0, "zeta_v": 0.7, "G_p": 1.5, "C_F_force": 0.03e-3},
             0.8, 0.3),
    # a light, soft, fast rig (a damper frame): 80 kg, 20 kN/m, 10 cm^2 piston, 120 Hz valve
    "rigC": ({"m": 80.0, "c": 50.0, "k": 20e3, "k_2": 10e3, "m_p": 5.0, "A": 10e-4, "K_a": 0.2e-12, "C_l": 1e-11,
              "K_v": 2.5e-3, "f_v": 120.0, "zeta_v": 0.8, "G_p": 1.2, "C_F_force": 0.6e-3}, 0.4, 0.01),
    # a small rig (issue 25, the blind piston-mass miss): 150 kg structure, 6 cm^2 piston, 50 Hz valve; a piston
    # of tens of kg is then a large share of the moving mass
    "rigD": ({"m": 150.0, "c": 200.0, "k": 50e3, "k_2": 25e3, "m_p": 5.0, "A": 6e-4, "K_a": 0.1e-12, "C_l": 1e-11,
              "K_v": 1.5e-3, "f_v": 50.0, "zeta_v": 0.8, "G_p": 1.2, "C_F_force": 0.6e-3}, 0.4, 0.02),
}


def base_truth(mode: str, rig: str = "paper") -> ip.Truth:
    tr = ip.Truth(c=1.1e3) if mode == "free" else ip.Truth()
    return replace(tr, **RIGS[rig][0])


def nominal_rig(mode: str, rig: str = "paper"):
    """The model the workflow is told to believe: the calibrated preset with the
    nonlinear effects of the paper's linear analysis switched off (for another
    rig: its own values of the keys ``RIGS`` lists)."""
    import servohydraulics as sh

    if mode == "free":
        r = sh.zhao2003(actuator_attached=False)
        r.effects.coulomb_friction = False
    else:
        r = sh.zhao2003()
        for e in ("coulomb_friction", "spring_softening", "load_pressure", "flow_nonlinearity"):
            setattr(r.effects, e, False)
    for key, v in RIGS[rig][0].items():
        setattr(r, key, float(v))
    return r


def nominal_file(mode: str, rig: str = "paper") -> str:
    return f"nominal_{mode}.toml" if rig == "paper" else f"nominal_{rig}_{mode}.toml"


# effect key -> (Truth overrides at a strength value, answer name, answer parameter, modes)
def hidden(key: str, val: float, peak_spool: float, m: float = 0.0) -> tuple[dict, str, dict, str]:
    """Truth overrides, the library name that should be found, the true parameter, the form
    (``m``: the rig's structure mass [kg])."""
    if key == "coulomb":
        return {"friction": "coulomb", "F_c": val}, "coulomb_friction", {"F_c": val}, "Coulomb (tanh)"
    if key == "stribeck":
        return ({"friction": "stribeck", "F_c": val, "F_s": 1.5 * val, "v_s": 0.01}, "coulomb_friction",
                {"F_c": "energy"}, "Stribeck, F_s = 1.5 F_c, v_s = 10 mm/s")
    if key in ("lugre", "lugre_stiff"):
        s0 = 5e5 if key == "lugre" else 2e6
        return ({"friction": "lugre", "F_c": val, "F_s": 1.3 * val, "v_s": 0.01, "sigma_0": s0},
                "lugre_friction", {"sigma_0": s0, "F_c": val},
                f"LuGre, sigma_0 = {s0:.0e} N/m, F_s = 1.3 F_c (presliding {1e3 * val / s0:.2f} mm)")
    if key == "viscous":
        return {"c": val}, "viscous_damping", {"c": val}, "viscous"
    if key == "spring":
        return {"spring_softening": True, "k_2": val}, "spring_softening", {"k_2": val}, "bilinear spring"
    if key == "load_pressure":
        return {"load_pressure": True, "p_s": val}, "load_pressure", {"p_s": val}, "Eq (3) square root"
    if key == "flow":
        return ({"flow": "rational", "b": val}, "flow_gain_nonlinearity", {"g_1": 1 / (1 + val)},
                f"rational curve b = {val:g}")
    if key == "flow_table":
        return ({"flow": "table", "table_opening": TABLE_OPENING, "table_flow": TABLE_FLOW},
                "flow_gain_nonlinearity", {"g_peak": "at_peak"}, "tabulated curve bending from 2 % opening")
    if key == "flow_knee":
        return ({"flow": "table", "table_opening": KNEE_OPENING, "table_flow": KNEE_FLOW},
                "flow_gain_nonlinearity", {"g_1": KNEE_FLOW[-1]}, "tabulated curve of the preset's kind (knee 10 %)")
    if key == "delay":
        return ({"delay": "pure", "tau": val}, "command_delay", {"command_delay": val},
                "continuous-time delay of the ZOH command")
    if key == "delay_filter":
        return ({"delay": "filter", "tau": val}, "command_delay", {"command_delay": val},
                "2nd-order Bessel filter of the command (tau: its DC group delay)")
    if key == "loop_delay":
        return ({"loop_delay": val}, "loop_delay", {"loop_delay": val},
                "true transport delay of the valve drive inside the loop")
    if key in ("bouc_wen", "bouc_wen_soft"):
        x_y = 3e-3 if key == "bouc_wen" else 6e-3  # yield displacement [m]; val: the yield force F_y [N]
        return ({"bouc_wen": True, "bw_k": val / x_y, "bw_A": 1.0, "bw_beta": 0.5 / x_y, "bw_gamma": 0.5 / x_y,
                 "bw_n": 1.0}, "bouc_wen_hysteresis", {"x_y": x_y, "F_y": val},
                f"Bouc-Wen specimen, yield {1e3 * x_y:g} mm")
    if key == "valve":
        return {"f_v": val}, "servovalve_dynamics", {"f_v": val}, "2nd-order valve"
    if key == "leakage":
        return {"C_l": val}, "leakage", {"C_l": val}, "laminar leakage"
    if key == "piston":
        return {"m_p": val}, "piston_mass", {"m_p": val}, "rigid mass"
    if key == "mass":  # val kg more mass on the load cell's structure side (the load cell measures its inertia)
        return ({"m": m + val}, "moving_mass", {"m": m + val},
                f"{val:g} kg the load cell sees (a piston on its actuator side)")
    if key == "spool":
        return {"x_v_max": val * peak_spool}, "spool_saturation", {"x_v_max": val * peak_spool}, "hard stop"
    raise ValueError(key)


def plan_new(snrs) -> list[dict]:
    """The cases added for issue 13: in-loop and command delays side by side, load pressure with 400 N of
    Coulomb friction, Bouc-Wen specimens, and rigs other than the paper's in displacement and force control."""
    singles = [
        # (key, mode, strengths, rig)
        ("loop_delay", "displacement", [0.004, 0.008], "paper"),
        ("delay", "displacement", [0.004], "paper"),
        ("bouc_wen", "displacement", [2000.0], "paper"),
        ("bouc_wen_soft", "displacement", [3000.0], "paper"),
        ("coulomb", "displacement", [300.0], "rigB"),
        ("loop_delay", "displacement", [0.004], "rigB"),
        ("viscous", "displacement", [2500.0], "rigB"),
        ("coulomb", "force", [300.0], "rigB"),
        # (a 25 or 30 Hz valve makes rigB's force loop unstable: a diverging record, nothing to diagnose)
        ("valve", "displacement", [20.0], "rigB"),
        ("viscous", "force", [2500.0], "rigB"),
        ("coulomb", "displacement", [20.0], "rigC"),
        ("bouc_wen", "displacement", [60.0], "rigC"),
        ("coulomb", "force", [20.0], "rigC"),
    ]
    nones = [("displacement", "rigB"), ("force", "rigB"), ("displacement", "rigC"), ("force", "rigC")]
    out = []
    for snr in snrs:
        for key, mode, strengths, rig in singles:
            for v in strengths:
                out.append({"kind": "single", "effects": [(key, v)], "mode": mode, "cmd": "std", "snr": snr,
                            "rig": rig, "set": "issue13"})
        for mode, rig in nones:
            out.append({"kind": "none", "effects": [], "mode": mode, "cmd": "std", "snr": snr, "rig": rig,
                        "set": "issue13"})
        out.append({"kind": "pair", "effects": [("load_pressure", 10e6), ("coulomb", 400.0)],
                    "mode": "displacement", "cmd": "std", "snr": snr, "set": "issue13"})
    return out


def plan_issue25(snrs_pairs=(55, 40), snrs_singles=(40, 30)) -> list[dict]:
    """The cases added for issue 25, of the kinds of the two blind misses at other magnitudes, rigs and seeds:
    a piston mass that is a large share of a small rig's moving mass (the load cell sees its inertia, F = p A -
    m_p a), and the load-pressure term with a second effect on records of large forces and low noise (the
    second effect ten or more times the force noise, named after the first).  ``cmd_scale`` enlarges the
    standard command (1.45: forces to about 67 kN on the paper's rig)."""
    singles = [
        # (key, mode, strength, rig)
        ("piston", "displacement", 60.0, "rigD"),
        ("piston", "displacement", 30.0, "rigD"),
        ("piston", "displacement", 120.0, "rigD"),
        ("piston", "force", 60.0, "rigD"),
        ("piston", "displacement", 40.0, "rigC"),
        # the blind miss itself: a piston whose inertia the load cell measures (F = p A), i.e. mass on the load
        # cell's structure side; the look-alikes (a piston behind the load cell, a softer oil column, the valve)
        # lower the oil-column frequency alike but leave the force's m a out
        ("mass", "displacement", 60.0, "rigD"),
        ("mass", "displacement", 25.0, "rigD"),
        ("mass", "force", 60.0, "rigD"),
        ("mass", "displacement", 40.0, "rigC"),
    ]
    pairs = [
        # (effects, rig, cmd_scale)
        ((("load_pressure", 10e6), ("coulomb", 400.0)), "paper", 1.45),
        ((("load_pressure", 12e6), ("coulomb", 250.0)), "paper", 1.7),
        ((("load_pressure", 8e6), ("coulomb", 600.0)), "paper", 1.3),
        ((("load_pressure", 10e6), ("viscous", 4000.0)), "paper", 1.45),
        ((("load_pressure", 8e6), ("coulomb", 300.0)), "rigB", 1.5),
        # the load pressure beyond the supply at the force peaks (1.15 p_s: the structure's inertia drives the
        # piston): the load-pressure candidate's range used to start above the peak load pressure
        ((("load_pressure", 7e6), ("coulomb", 400.0)), "paper", 1.45),
    ]
    out = []
    for snr in snrs_singles:
        for key, mode, v, rig in singles:
            out.append({"kind": "single", "effects": [(key, v)], "mode": mode, "cmd": "std", "snr": snr, "rig": rig,
                        "set": "issue25"})
        out.append({"kind": "none", "effects": [], "mode": "displacement", "cmd": "std", "snr": snr, "rig": "rigD",
                    "set": "issue25"})
    for snr in snrs_pairs:
        for effects, rig, scale in pairs:
            out.append({"kind": "pair", "effects": list(effects), "mode": "displacement", "cmd": "std", "snr": snr,
                        "rig": rig, "cmd_scale": scale, "set": "issue25"})
    return out


def plan(size: str, cases: str = "all") -> list[dict]:
    """The records: single effects at graded strengths, no effect, two effects."""
    singles = [
        # (key, mode, strengths)
        ("coulomb", "displacement", [150.0, 400.0]),
        ("stribeck", "displacement", [250.0]),
        ("lugre", "displacement", [250.0, 400.0]),
        ("lugre_stiff", "displacement", [150.0]),
        ("coulomb", "free", [95.7]),
        ("stribeck", "free", [95.7]),
        ("viscous", "displacement", [5000.0, 9000.0]),
        ("viscous", "free", [2500.0]),
        ("spring", "displacement", [350.4e3]),
        ("load_pressure", "displacement", [8e6, 12e6]),
        ("flow", "displacement", [0.6, 2.0]),
        ("flow", "force", [1.0]),
        ("flow_table", "force", [0.0]),
        ("flow_knee", "force", [0.0]),
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
    if cases == "new":
        return plan_new(snrs)
    if cases == "issue25":
        return plan_issue25()
    out = []
    for snr in snrs:
        for key, mode, strengths in singles:
            for v in strengths:
                # the preset-kind curve is linear below 10 % opening: its record must open the spool beyond that
                cmd = {"flow_table": "sweep", "flow_knee": "bigsweep"}.get(key, "std")
                out.append({"kind": "single", "effects": [(key, v)], "mode": mode, "cmd": cmd, "snr": snr})
        for mode, cmd in nones:
            out.append({"kind": "none", "effects": [], "mode": mode, "cmd": cmd, "snr": snr})
        for a, b in pairs:
            out.append({"kind": "pair", "effects": [a, b], "mode": "displacement", "cmd": "std", "snr": snr})
    return out + (plan_new(snrs) + plan_issue25() if cases == "all" else [])


IN_LIBRARY = {"coulomb", "viscous", "spring", "load_pressure", "flow", "delay", "valve", "leakage", "piston",
              "spool", "bouc_wen", "bouc_wen_soft", "mass"}
#: (IN_LIBRARY: forms the library has exactly; the others are out-of-library forms)


def make_record(args: tuple) -> tuple[dict, dict, dict]:
    """One record (run in a worker process): (channels with noise, manifest entry, answer-key entry)."""
    i, it, seed, duration = args
    rng = np.random.default_rng([seed, i])
    rid = f"r{i:03d}"
    mode = it["mode"]
    rig = it.get("rig", "paper")
    dur = it.get("duration", duration)
    u, x0 = command(mode, it["cmd"], dur, rng)
    u = u * RIGS[rig][1 if mode == "displacement" else 2] * it.get("cmd_scale", 1.0) if mode != "free" else u
    tr = base_truth(mode, rig)
    peak = float(np.max(np.abs(ip.simulate(tr, mode, u, DT, x0, substeps=2)["spool"]))) \
        if any(k == "spool" for k, _ in it["effects"]) else 0.0
    answers, forms, over = [], [], {}
    for k, v in it["effects"]:
        o, name, par, form = hidden(k, v, peak, tr.m)
        over.update(o)
        answers.append({"name": name, "parameters": par, "form": k, "in_library": k in IN_LIBRARY})
        forms.append(f"{k}: {form}")
    tr = replace(tr, **over)
    ch = ip.simulate(tr, mode, u, DT, x0, substeps=SUBSTEPS)
    v = ch["velocity"]
    f_eq = float(np.sum(ch["friction"] * v) / max(np.sum(np.abs(v)), 1e-30))
    for a in answers:
        if a["parameters"].get("g_peak") == "at_peak":
            # the record never opens the spool near 1: judge the curve where the record used it
            xp = float(np.max(np.abs(ch["spool"])))
            a["opening"] = xp
            a["parameters"] = {"g_peak": float(np.interp(xp, TABLE_OPENING, TABLE_FLOW))}
            a["alt_parameters"] = {"g_1": TABLE_FLOW[-1]}
            a["alt_label"] = "full opening, not reached"
            a["truth_note"] = "g_peak: g(x) at the record's peak opening x; alt: g(1), outside the record"
        if a["parameters"].get("F_c") == "energy":
            a["parameters"] = {"F_c": f_eq}
            a["alt_parameters"] = {"F_c": tr.F_c}  # the sliding Coulomb level
            a["alt_label"] = "sliding level"
            a["truth_note"] = "F_c: energy-equivalent Coulomb force; alt: sliding Coulomb level"
    rec = {"time": ch["time"], "command": ch["command"]}
    for c in ("displacement", "force"):
        y = ch[c]
        rms = float(np.sqrt(np.mean(y ** 2)))
        noise = rms * 10 ** (-it["snr"] / 20) if rms > 0 and not (c == "force" and mode == "free") else 0.0
        rec[c] = y + rng.normal(0.0, noise, y.size) if noise > 0 else y.copy()
    key = {"id": rid, "kind": it["kind"], "mode": mode, "snr": it["snr"], "answers": answers,
           "forms": forms, "duration": dur, "rig": rig, "set": it.get("set", "earlier"),
           "runtime_check": it.get("runtime_check", False),
           "peak_spool": float(np.max(np.abs(ch["spool"]))), "friction_energy_equivalent": f_eq,
           "truth": {k: v for k, v in asdict(tr).items() if not isinstance(v, list)}}
    return rec, {"id": rid, "mode": mode, "rig": nominal_file(mode, rig)}, key


SUBSTEPS = 4  #: RK4 substeps a 0.5 ms sample in the generator (125 us: h times the fastest rate < 0.1)


def generate(out: Path, size: str = "default", seed: int = 2003, duration: float = 4.0, jobs: int = 2,
             cases: str = "all") -> None:
    import servohydraulics as sh
    from servohydraulics.workers import check_workers, process_pool

    check_workers(jobs, "--jobs")  # 1 .. cpu_count, before any file is written (a large count forks without bound)
    out.mkdir(parents=True, exist_ok=True)
    (out / "records").mkdir(exist_ok=True)
    for rig in RIGS:
        for mode in (("displacement", "force", "free") if rig == "paper" else ("displacement", "force")):
            sh.save_rig(nominal_rig(mode, rig), out / nominal_file(mode, rig))
    items = plan(size, cases)
    # the 10 s, 2 kHz runtime record
    items.append({"kind": "single", "effects": [("coulomb", 300.0)], "mode": "displacement", "cmd": "std",
                  "snr": 30, "duration": 10.0, "runtime_check": True})
    manifest, key = [], []
    with process_pool(jobs, "--jobs") as ex:  # workers that die with this process
        for rec, man, k in ex.map(make_record, [(i, it, seed, duration) for i, it in enumerate(items)]):
            path = out / "records" / f"{man['id']}.csv"
            sh.write_record(path, rec)
            man["record"] = str(path.relative_to(out))
            manifest.append(man)
            key.append(k)
            print(f"{k['id']} {k['mode']:12s} snr {k['snr']} {k['kind']:6s} {', '.join(k['forms']) or 'none'}",
                  flush=True)
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1))
    args = f"--out {out} --size {size} --seed {seed} --duration {duration:g} --cases {cases}"
    (out / "generate.json").write_text(json.dumps({"command": f"python evaluation/diagnose_eval/generate.py {args}"}))
    (out / "answer_key.json").write_text(json.dumps(key, indent=1))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default="build/diagnose_eval")
    p.add_argument("--size", choices=["default", "quick"], default="default")
    p.add_argument("--seed", type=int, default=2003)
    p.add_argument("--duration", type=float, default=4.0, help="record length [s]")
    p.add_argument("--jobs", type=int, default=2, help="worker processes")
    p.add_argument("--cases", choices=["all", "new", "old", "issue25"], default="all",
                   help="all cases, only those added for issue 13 (new) or 25, or only the earlier ones")
    a = p.parse_args()
    try:
        generate(Path(a.out), a.size, a.seed, a.duration, a.jobs, a.cases)
    except ValueError as e:  # a bad --jobs: one line, exit 2
        p.error(str(e))


if __name__ == "__main__":
    main()
