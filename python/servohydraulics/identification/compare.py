"""Compare a rig with a lab record: the record's command simulated through the
rig, from the record's initial state, against what was measured.

Per channel: ``nrmse_pct`` = 100 rms(sim - measured) / std(measured) (the
issue's definition), ``nrmse_demeaned_pct`` (the same with the error's mean
removed, the UTFSM README's figure), and the gain and phase of the measured
and simulated frequency responses channel/command (H1, with coherence) at a
set of frequencies.  ``checks`` are the record's plausibility checks (:mod:`.checks`: an
error-level one stops the comparison before the run) and the simulated run's warnings (the
limits it hit, the solver's notes), in the JSON and on the command line's stderr;
``warnings`` keeps the run's warnings as plain text.
``Comparison.write(out)`` writes ``comparison.json``, ``overlay.png``, ``frf.png`` and, with a
force channel, ``loops.png``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import FileSet, check_folder, write_text
from ..response import Response
from ..rig import Rig
from .checks import gate, run_checks, scale_checks, settle
from .frf import FrequencyResponse, command_band, gain_phase, h1
from .run import (
    CHANNELS,
    check_record,
    controller_ratio,
    nrmse_demeaned_pct,
    nrmse_pct,
    record_name,
    record_rig,
    simulate_record,
)

#: default frequencies of the reported FRF points [Hz] (those above the command's band are dropped)
FREQUENCIES = (0.5, 1.0, 2.0, 5.0, 8.0, 10.0, 12.0, 15.0, 18.0, 20.0, 30.0, 50.0, 100.0)


def channels_of(record: Response, mode: str) -> tuple[str, ...]:
    """The channels of ``CHANNELS`` the record carries with some variation."""
    out = tuple(c for c in CHANNELS if c in record.channels and np.std(record.channels[c]) > 0)
    if not out:
        raise ValueError(f"{record.path or record_name(record)}: no measured channel among {list(CHANNELS)} "
                         "varies")
    return out


@dataclass(eq=False)
class Comparison:
    """A rig against a record (SI units); see the module docstring."""

    name: str
    mode: str
    time: np.ndarray = field(repr=False)
    measured: dict = field(repr=False)
    simulated: dict = field(repr=False)
    frf_measured: dict = field(repr=False)
    frf_simulated: dict = field(repr=False)
    frequencies: np.ndarray = field(repr=False)
    f_max: float = 0.0
    channels: dict = field(default_factory=dict)  #: channel -> metrics (the JSON's "channels")
    warnings: list = field(default_factory=list)  #: the simulated run's limits and solver notes (``Response.warnings``)
    checks: list = field(default_factory=list)  #: ``checks.Check``: the record's plausibility and the run's limits
    command: np.ndarray | None = field(default=None, repr=False)  #: the record's command (for the zoom windows)
    field_input: dict | None = None  #: the MR damper field input of the record (input, value, unit, law), or None

    def nrmse(self, channel: str) -> float:
        return self.channels[channel]["nrmse_pct"]

    def to_dict(self) -> dict[str, Any]:
        return {"record": self.name, "mode": self.mode, "samples": int(self.time.size),
                "dt_s": float(self.time[1] - self.time[0]), "command_band_hz": self.f_max,
                "definition": "nrmse_pct = 100 rms(sim - measured) / std(measured); nrmse_demeaned_pct: the "
                              "error's mean removed; frf: H1 = S_uy/S_uu (Welch, Hann, nperseg) of channel/command",
                "warnings": self.warnings, "checks": [c.to_dict() for c in self.checks], "field": self.field_input,
                "channels": self.channels}

    def figure_names(self) -> list[str]:
        """The figures :meth:`write` writes (``NAME.png``)."""
        return ["overlay", "frf"] + (["loops"] if "force" in self.measured and "displacement" in self.measured
                                     else [])

    def figures(self) -> dict:
        """The comparison's figures by name (``figure_names``): ``matplotlib.figure.Figure`` objects."""
        from .figures import frf_figure, loops_figure, overlay_figure

        unit = "N" if self.mode == "force" else "m"
        figs = {"overlay": overlay_figure(self.time, self.measured, self.simulated,
                                          f"{self.name}: measured and simulated (lettered: where they part most)",
                                          command=self.command),
                "frf": frf_figure(self.frf_measured, self.frf_simulated, 1.2 * self.f_max,
                                  f"{self.name}: frequency response (H1)", unit)}
        if "loops" in self.figure_names():
            figs["loops"] = loops_figure(self.time, self.measured, self.simulated,
                                         f"{self.name}: force loops, measured and simulated", command=self.command)
        return figs

    def write(self, out: str | Path) -> Path:
        """Writes ``comparison.json`` and the figures (``overlay.png``, ``frf.png``, ``loops.png``
        with a force channel) into ``out``, as one ``atomic.FileSet``: all of them, or (an
        OSError naming the file) none."""
        out = check_folder(out)
        figs = self.figures()
        with FileSet() as files:
            write_json(out / "comparison.json", self.to_dict(), files)
            save_figures(files, {out / f"{name}.png": fig for name, fig in figs.items()})
        return out / "comparison.json"


def finite_or_none(obj):
    """``obj`` with every non-finite float replaced by None (JSON null: not determined,
    e.g. the interval of a key the records do not constrain)."""
    if isinstance(obj, dict):
        return {k: finite_or_none(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_or_none(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def write_json(path: Path, data: dict, files: FileSet | None = None) -> Path:
    """Writes JSON atomically (``atomic.write_text``: never a half-written file; into ``files``
    when given, renamed with the rest of its set); non-finite numbers become null."""
    text = json.dumps(finite_or_none(data), indent=2, allow_nan=False) + "\n"
    return files.write_text(path, text) if files is not None else write_text(path, text)


def save_figures(files: FileSet, figures: dict) -> None:
    """Saves each figure (PNG, 110 dpi) to its path through ``files``."""
    for path, fig in figures.items():
        fig.savefig(files.path(path), dpi=110, format="png")


def frf_points(measured: FrequencyResponse, simulated: FrequencyResponse, frequencies: np.ndarray) -> dict:
    """Gain [-] and phase [deg] of measured and simulated at the frequencies, with coherence."""
    hm, cm = measured.at(frequencies)
    hs, cs = simulated.at(frequencies)
    gm, pm = gain_phase(hm)
    gs, ps = gain_phase(hs)
    r = lambda a: [round(float(v), 6) for v in a]  # noqa: E731
    return {"frequency_hz": r(frequencies), "measured_gain": r(gm), "measured_phase_deg": r(pm),
            "simulated_gain": r(gs), "simulated_phase_deg": r(ps), "measured_coherence": r(cm),
            "simulated_coherence": r(cs), "gain_ratio": r(gs / gm), "phase_difference_deg": r(ps - pm)}


def compare(record: Response, rig: Rig, mode: str, dt: float | None = None, options=None,
            frequencies=None, simulated: Response | None = None, accept=None, check: bool = True,
            current: float | None = None, voltage: float | None = None) -> Comparison:
    """Simulates the record's command through the rig and compares (see the module docstring).

    Args:
        record: a record (``read_record``) with time, command, displacement, force.
        rig: the rig; mode: its control mode (``"displacement"`` or ``"force"``).
        dt: controller sample time [s] (default: the record's).
        options: solver options (default: CVODE BDF).
        frequencies: FRF points [Hz] (default ``FREQUENCIES`` up to the command's band).
        simulated: the record already simulated (``run.simulate_record``; skips the run).
        accept: codes of warning-level checks the user acknowledges (``checks.CODES``).
        check: run the record's plausibility checks first (``checks.record_checks``; an error
            raises ``checks.CheckError``, a ValueError); ``identify`` checks its records once itself.
        current, voltage: the MR damper's coil current [A] or voltage [V] the record was made at (its
            law predicts the damper there, ``law.predict_at``; a value outside the range the law was
            identified on is reported in ``warnings``); ValueError naming the flag when the rig has
            no MR damper, its law reads the other input, or the value is not a finite number >= 0.
    """
    from .law import FIELD_INPUTS, choice_name, predict_at, rig_field

    rig = predict_at(rig, current, voltage)
    if mode not in ("displacement", "force"):
        raise ValueError(f"invalid mode = {mode!r}: a record compares in 'displacement' or 'force' control")
    check_record(record)
    controller_ratio(record.dt, record.time.size, dt)
    chans = channels_of(record, mode)
    found = gate([record], rig, mode, dt, accept) if check else []
    sim = simulated if simulated is not None else simulate_record(rig, record, mode, dt=dt, options=options)
    u = np.asarray(record.command, dtype=float)
    f_max = command_band(u, record.dt)
    freq = np.asarray(frequencies if frequencies is not None else [f for f in FREQUENCIES if f <= 1.05 * f_max],
                      dtype=float)
    out = Comparison(name=record_name(record), mode=mode, time=np.asarray(record.time), measured={}, simulated={},
                     command=u,
                     frf_measured={}, frf_simulated={}, frequencies=freq, f_max=f_max,
                     warnings=sim.warnings(record_rig(rig, record)),
                     checks=found + settle(run_checks(sim, record_rig(rig, record),
                                                      str(record.path or record_name(record))), accept))
    if rig.effects.mr_damper:
        kind, value = rig_field(rig)
        out.field_input = {"input": kind, "value": value, "unit": FIELD_INPUTS[kind][1],
                     "law": choice_name(rig, "mr_law"), "given": current is not None or voltage is not None}
    for ch in chans:
        m, s = np.asarray(record.channels[ch], dtype=float), np.asarray(sim.channels[ch], dtype=float)
        out.measured[ch], out.simulated[ch] = m, s
        out.frf_measured[ch], out.frf_simulated[ch] = h1(u, m, record.dt), h1(u, s, record.dt)
        out.channels[ch] = {"nrmse_pct": nrmse_pct(s, m), "nrmse_demeaned_pct": nrmse_demeaned_pct(s, m),
                            "rms_error": float(np.sqrt(np.mean((s - m) ** 2))), "std_measured": float(np.std(m)),
                            "unit": {"displacement": "m", "force": "N"}[ch],
                            "frf": frf_points(out.frf_measured[ch], out.frf_simulated[ch], freq)}
    if check:
        out.checks += settle(scale_checks(out.measured, out.simulated, str(record.path or record_name(record))),
                             accept)
    return out


__all__ = ["FREQUENCIES", "Comparison", "channels_of", "compare", "frf_points", "record_name", "write_json"]
