"""Why two held-out forces of the UTFSM table still lose (docs/lab-records.md).

    SH_SHARED_DIR=../shared PYTHONPATH=python python evaluation/utfsm_losses.py [--extra-keys] [--band]

For each held-out pair, the committed rig (evaluation/utfsm_rigs/, made by
evaluation/utfsm_eval.py) predicts the held-out record's force from its
command; printed: the NRMSE, the least-squares gain g of measured ~ g x
predicted and the NRMSE at that gain (a level difference between the records),
and, over six equal stretches of the record (the sweep's frequency rises with
time), the time shift of the predicted force in whole samples (-6 ... 6 ms)
that fits best (a lag or lead of the hysteresis).  A diagnostic only: the gain
and shifts are not part of the model.  ``--extra-keys`` also identifies the 1 A
chirp again with a force measurement delay, ``mr_n`` and ``mr_k0`` fitted too
(start 1 ms, 2, 1 kN/m) and prints its held-out sweep NRMSE, then again with
the default keys from the thesis' 1 A parameters as the start (about 3 min).

Always printed as well (about 30 s, no identification):

* the campaigns' damper response in the measured data alone: H1 of the measured
  force over the measured displacement (``lab.h1``, 4096-point segments) at
  2-14 Hz, its gain ratio and phase difference June chirp / May sweep at each
  current; as a control, the same figures for the thesis' Bouc-Wen model (one
  model) driven by each record's measured displacement, i.e. what the two
  excitations alone would make differ;
* each committed rig's damper (its Spencer keys and mass ``m``, back in the
  thesis' units) driven by the held-out record's MEASURED displacement, as the
  thesis' model is: whether the loss comes from our simulated displacement or
  from the damper.

``--band`` identifies each record again (generic start, default keys) on the
part of it whose command frequency stays below the held-out command's band
(``identification.frf.command_band``: 99 % of its energy below it): the record cut at the first
time the command's dominant frequency (STFT peak, 2048-sample Hann windows,
75 % overlap) exceeds it (the chirps at 44-47 s for the sweeps' 14.7 Hz; the
sweeps are not cut for the chirps' 20.1 Hz), and prints the held-out NRMSE; at
1 A also with the extra keys of ``--extra-keys`` (about 5 min in all).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"
PAIRS = (("chirp20Hz_0A", "sweep15Hz_0A"), ("sweep15Hz_0A", "chirp20Hz_0A"),
         ("chirp20Hz_1A", "sweep15Hz_1A"), ("sweep15Hz_1A", "chirp20Hz_1A"))


def best_shift(sim: np.ndarray, meas: np.ndarray, idx: np.ndarray, span: int = 6) -> int:
    """The shift d [samples] minimising sum((sim[k - d] - meas[k])^2) over idx (d > 0: sim delayed)."""
    return min(range(-span, span + 1), key=lambda d: float(np.sum((np.roll(sim, d)[idx] - meas[idx]) ** 2)))


def main() -> int:
    sys.path.insert(0, str(ROOT / "python"))
    import servohydraulics as sh
    from servohydraulics import identification as lab
    from servohydraulics.identification.fit import fit_options

    if not DATA.is_dir():
        print(f"UTFSM records not found in {DATA}", file=sys.stderr)
        return 2
    for train, test in PAIRS:
        rec = sh.read_record(DATA / f"{test}.csv")
        rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rigs" / f"identified_from_{train}.toml")
        sim = lab.simulate_record(rig, rec, "displacement", options=fit_options(rig, [rec], "displacement")).force
        meas = np.asarray(rec.force, dtype=float)
        g = float(sim @ meas / (sim @ sim))
        stretches = np.array_split(np.arange(2000, meas.size - 2000), 6)
        shifts = [best_shift(sim, meas, s) for s in stretches]
        print(f"{train} -> {test}: force NRMSE {lab.nrmse_pct(sim, meas):.2f} %, best gain {g:.3f} "
              f"(NRMSE {lab.nrmse_pct(g * sim, meas):.2f} %), best shift per sixth of the record [ms]: {shifts}")
    campaigns(sh, lab)
    measured_motion(sh, lab)
    if "--extra-keys" in sys.argv[1:]:
        extra_keys(sh, lab, fit_options)
    if "--band" in sys.argv[1:]:
        band(sh, lab, fit_options)
    return 0


CURRENT = {"0A": 0.0, "1A": 1.0}
FREQUENCIES = np.array([2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0])


def campaigns(sh, lab) -> None:
    from servohydraulics.identification import baselines

    print("force / measured displacement, June chirp vs May sweep (H1, 4096-point segments) at "
          + ", ".join(f"{f:g}" for f in FREQUENCIES) + " Hz:")
    for cur, amps in CURRENT.items():
        h = {}
        for name in (f"chirp20Hz_{cur}", f"sweep15Hz_{cur}"):
            rec = sh.read_record(DATA / f"{name}.csv")
            model = baselines.thesis_mr_force(rec.displacement, rec.dt, amps)
            h[name] = [lab.h1(rec.displacement, y, rec.dt, nperseg=4096).at(FREQUENCIES)[0]
                       for y in (rec.force, model)]
        (june, june_model), (may, may_model) = h.values()
        print(f"  {cur}: measured |F/x| June {fmt(np.abs(june) / 1e3, '.0f')} N/mm, May "
              f"{fmt(np.abs(may) / 1e3, '.0f')} N/mm; gain ratio June/May {fmt(np.abs(june / may), '.2f')}, "
              f"phase June - May {fmt(np.degrees(np.angle(june / may)), '.1f')} deg; the thesis' model driven by "
              f"each record's displacement: ratio {fmt(np.abs(june_model / may_model), '.2f')}, phase "
              f"{fmt(np.degrees(np.angle(june_model / may_model)), '.1f')} deg")


def fmt(values, spec: str) -> str:
    return " ".join(format(float(v), spec) for v in values)


def rig_spencer(rig, baselines):
    """The rig's Spencer keys in the thesis' units (the inverse of ``baselines.spencer_rig_keys``)."""
    n = rig.mr_n
    p = baselines.SpencerParameters(alpha=rig.mr_alpha_a / 1e3, c0=rig.mr_c0_a / 1e3, c1=rig.mr_c1_a / 1e3,
                                    k0=rig.mr_k0 / 1e3, k1=rig.mr_k1 / 1e3, x0=rig.mr_x0 * 1e3, A=rig.mr_A,
                                    beta=rig.mr_beta / 1e3**n, gamma=rig.mr_gamma / 1e3**n, n=n)
    back = baselines.spencer_rig_keys(p)
    for k in ("mr_alpha_a", "mr_c0_a", "mr_c1_a", "mr_k0", "mr_k1", "mr_x0", "mr_beta", "mr_gamma"):
        assert np.isclose(back[k], getattr(rig, k), rtol=1e-12, atol=0.0), k
    assert rig.mr_alpha_b == rig.mr_c0_b == rig.mr_c1_b == 0.0 or rig.mr_voltage == 0.0
    return p


def measured_motion(sh, lab) -> None:
    from servohydraulics.identification import baselines

    print("each committed rig's damper (+ m a) driven by the MEASURED displacement (as the thesis' model is):")
    for train, test in PAIRS:
        rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rigs" / f"identified_from_{train}.toml")
        p = rig_spencer(rig, baselines)
        row = []
        for name in (train, test):
            rec = sh.read_record(DATA / f"{name}.csv")
            _, v = baselines.smoothed_motion(rec.displacement, rec.dt)
            force = baselines.spencer_force(rec.displacement, rec.dt, p) + rig.m * np.gradient(v, rec.dt)
            row.append(lab.nrmse_pct(force, rec.force))
        print(f"  {train} -> {test}: force NRMSE {row[1]:.2f} % held out ({row[0]:.2f} % on {train} itself)")


def cut_below(rec, f_max: float):
    """The record up to the first time its command's dominant frequency exceeds f_max [Hz]."""
    from scipy import signal

    from servohydraulics.response import Response

    u = np.asarray(rec.command, dtype=float)
    f, t, z = signal.stft(u - u.mean(), fs=1.0 / rec.dt, nperseg=2048, noverlap=1536)
    above = np.flatnonzero(f[np.argmax(np.abs(z), axis=0)] > f_max)
    n = u.size if above.size == 0 else min(u.size, int(round(t[above[0]] / rec.dt)))
    return Response({k: np.asarray(v)[:n] for k, v in rec.channels.items()}, kind="record"), n * rec.dt


def band(sh, lab, fit_options) -> None:
    from servohydraulics.identification import coordinates as keys
    from servohydraulics.identification.frf import command_band

    default = keys.LOOP_KEYS["displacement"] + keys.SPECIMEN_KEYS["mr_damper"]
    extra = ("measurement_delay_force", "mr_n", "mr_k0")
    for train, test in PAIRS:
        rec, held = (sh.read_record(DATA / f"{n}.csv") for n in (train, test))
        f_max = command_band(held.command, held.dt)
        cut, t_cut = cut_below(rec, f_max)
        runs = [("default keys", None, default)]
        if train == "chirp20Hz_1A":
            runs.append(("extra keys", {"measurement_delay_force": 1e-3, "mr_k0": 1e3}, default + extra))
        for label, start, fit in runs:
            rig = None if start is None else started_rig(cut, start)
            ident = sh.identify([cut], rig=rig, fit=fit, mode="displacement", specimen="mr_damper", progress=False)
            pred, whole = (lab.compare(r, ident.rig, "displacement",
                                       options=fit_options(ident.rig, [r], "displacement")) for r in (held, rec))
            print(f"{train} below {f_max:.2f} Hz (first {t_cut:.1f} of {rec.time[-1]:.1f} s), {label}: held-out "
                  f"{test} displacement {pred.nrmse('displacement'):.2f} %, force {pred.nrmse('force'):.2f} %; "
                  f"whole {train} displacement {whole.nrmse('displacement'):.2f} %, force "
                  f"{whole.nrmse('force'):.2f} %")


def started_rig(record, start: dict):
    """The generic rig scaled from ``record`` with the MR damper's start, then the ``start`` keys."""
    from servohydraulics.identification import generic

    rig = generic.generic_rig(record)
    generic.mr_damper_start(rig, record)
    rig.effects.mr_damper = True
    for k, v in start.items():
        setattr(rig, k, v)
    return rig


def extra_keys(sh, lab, fit_options) -> None:
    from servohydraulics.identification import baselines
    from servohydraulics.identification import coordinates as keys

    train, test = (sh.read_record(DATA / f"{n}.csv") for n in ("chirp20Hz_1A", "sweep15Hz_1A"))
    default = keys.LOOP_KEYS["displacement"] + keys.SPECIMEN_KEYS["mr_damper"]
    extra = ("measurement_delay_force", "mr_n", "mr_k0")
    for label, start, fit in (("extra keys", {"measurement_delay_force": 1e-3, "mr_k0": 1e3}, default + extra),
                              ("thesis start", baselines.spencer_rig_keys(baselines.thesis_mr_parameters(1.0)),
                               default)):
        rig = started_rig(train, start)
        ident = sh.identify([train], rig=rig, fit=fit, mode="displacement", specimen="mr_damper", progress=False)
        pred = lab.compare(test, ident.rig, "displacement", options=fit_options(ident.rig, [test], "displacement"))
        print(f"chirp20Hz_1A, {label}: " + ", ".join(f"{k} = {ident.values[k]:.4g}" for k in fit[3:])
              + f"; fit force {ident.after[0].nrmse('force'):.2f} %, held-out sweep15Hz_1A force "
              f"{pred.nrmse('force'):.2f} %, displacement {pred.nrmse('displacement'):.2f} %")


if __name__ == "__main__":
    sys.exit(main())
