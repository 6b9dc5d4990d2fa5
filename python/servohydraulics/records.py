"""Lab records as CSV: a header row, then one row per sample, SI units.

Required columns: ``time`` [s], ``command`` [m in displacement control, N in
force control], ``displacement`` [m], ``force`` [N].  Optional: ``velocity``
[m/s], ``acceleration`` [m/s^2], ``pressure`` [Pa], ``spool`` [-], ``drive``
[V], ``flow`` [m^3/s], ``ground_accel`` [m/s^2].  Time must be uniform and
increasing.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

REQUIRED = ("time", "command", "displacement", "force")
OPTIONAL = ("velocity", "acceleration", "pressure", "spool", "drive", "flow", "ground_accel")
UNITS = {"time": "s", "command": "m or N", "displacement": "m", "force": "N", "velocity": "m/s",
         "acceleration": "m/s^2", "pressure": "Pa", "spool": "-", "drive": "V", "flow": "m^3/s",
         "ground_accel": "m/s^2"}


@dataclass
class Record:
    """A lab (or simulated) record: named channels of equal length."""

    channels: dict[str, np.ndarray]
    path: Path | None = None

    def __getattr__(self, name: str) -> np.ndarray:
        try:
            return self.__dict__["channels"][name]
        except KeyError:
            raise AttributeError(f"record has no channel {name!r}") from None

    @property
    def dt(self) -> float:
        t = self.channels["time"]
        return float((t[-1] - t[0]) / (len(t) - 1))

    def __len__(self) -> int:
        return len(self.channels["time"])


def _check_time(t: np.ndarray, where: str) -> None:
    if t.size < 2:
        raise ValueError(f"{where}: a record needs at least 2 rows, got {t.size}")
    d = np.diff(t)
    if np.any(d <= 0):
        i = int(np.flatnonzero(d <= 0)[0])
        raise ValueError(f"{where}: time must be increasing; time[{i + 1}] = {t[i + 1]} <= time[{i}] = {t[i]}")
    dt = (t[-1] - t[0]) / (t.size - 1)
    worst = int(np.argmax(np.abs(d - dt)))
    if abs(d[worst] - dt) > 1e-6 * dt + 1e-12:
        raise ValueError(f"{where}: time must be uniform; step {worst} is {d[worst]:.9g} s, "
                         f"the mean step is {dt:.9g} s")


def read_record(path: str | Path) -> Record:
    """Reads a record CSV; errors name the file, column and row."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"record file not found: {path}")
    with path.open() as f:
        header = f.readline().strip()
    names = [h.strip() for h in header.split(",")]
    missing = [c for c in REQUIRED if c not in names]
    if missing:
        raise ValueError(f"{path}: missing column(s) {missing}; the header must have {list(REQUIRED)}")
    unknown = [c for c in names if c not in REQUIRED + OPTIONAL]
    if unknown:
        raise ValueError(f"{path}: unknown column(s) {unknown}; allowed: {list(REQUIRED + OPTIONAL)}")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as e:
        raise ValueError(f"{path}: could not parse numbers: {e}") from None
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: {data.shape[1]} values per row but {len(names)} header columns")
    channels = {n: data[:, i].copy() for i, n in enumerate(names)}
    for n, v in channels.items():
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValueError(f"{path}: column {n!r} row {bad[0] + 2} is {v[bad[0]]} (must be finite)")
    _check_time(channels["time"], str(path))
    return Record(channels, path)


def write_record(path: str | Path, record) -> Path:
    """Writes a record CSV from a Record, a SimulationResult or a dict of arrays."""
    path = Path(path)
    if isinstance(record, Record):
        ch = record.channels
    elif isinstance(record, dict):
        ch = record
    else:
        ch = {n: getattr(record, n) for n in REQUIRED + OPTIONAL if hasattr(record, n)}
    missing = [c for c in REQUIRED if c not in ch]
    if missing:
        raise ValueError(f"cannot write {path}: missing channel(s) {missing}")
    names = [n for n in REQUIRED + OPTIONAL if n in ch]
    cols = [np.asarray(ch[n], dtype=float) for n in names]
    n0 = cols[0].size
    for n, c in zip(names, cols):
        if c.shape != (n0,):
            raise ValueError(f"cannot write {path}: channel {n!r} has shape {c.shape}, expected ({n0},)")
        if not np.all(np.isfinite(c)):
            raise ValueError(f"cannot write {path}: channel {n!r} has non-finite values")
    _check_time(cols[0], f"cannot write {path}")
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    return path
