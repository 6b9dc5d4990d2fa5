"""Lab records as CSV: a header row, then one row per sample, SI units.

Required columns: ``time`` [s], ``command`` [m in displacement control, N in
force control], ``displacement`` [m], ``force`` [N].  Optional: any other
channel of a run (``channel_units("record")``: ``velocity`` [m/s],
``acceleration`` [m/s^2], ``pressure`` [Pa], ``spool`` [-], ``drive`` [V],
``flow`` [m^3/s], ``ground_acceleration`` [m/s^2], the EFT and RPsD channels,
``flags``...).  Time must be uniform and increasing.  The old column name
``ground_accel`` is read as ``ground_acceleration`` for one release.

Lab files that name their columns with the unit appended (``time_s``,
``command_m``, ``command_N``, ``displacement_m``, ``force_N``: the UTFSM
records of docs/lab-records.md) are read under the project's names
(``UNIT_SUFFIXED_COLUMNS``); the suffix must be the channel's SI unit.

A record is a :class:`~servohydraulics.response.Response` of kind ``"record"``;
``write_record(path, r)`` is ``r.to_csv(path)``.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from .response import DEPRECATED_COLUMNS, REQUIRED, Response, channel_units, uniform_dt

#: Deprecated name of a record: records are Responses of kind "record".
Record = Response


#: Unit-suffixed column names read as the project's channel names (SI units only).
UNIT_SUFFIXED_COLUMNS = {"time_s": "time", "command_m": "command", "command_N": "command",
                         "displacement_m": "displacement", "force_N": "force"}


def _columns(path: Path, header: str) -> list[str]:
    names = [UNIT_SUFFIXED_COLUMNS.get(h.strip(), h.strip()) for h in header.split(",")]
    seen: set[str] = set()
    for i, n in enumerate(names):
        if n in seen:
            raise ValueError(f"{path}: column {n!r} appears twice in the header (columns {i + 1} and "
                             f"{names.index(n) + 1})")
        seen.add(n)
        if n in DEPRECATED_COLUMNS:
            warnings.warn(f"{path}: column {n!r} is deprecated; name it {DEPRECATED_COLUMNS[n]!r}",
                          DeprecationWarning, stacklevel=3)
            names[i] = DEPRECATED_COLUMNS[n]
    missing = [c for c in REQUIRED if c not in names]
    if missing:
        raise ValueError(f"{path}: missing column(s) {missing}; the header must have {list(REQUIRED)}")
    allowed = channel_units("record")
    unknown = [c for c in names if c not in allowed]
    if unknown:
        raise ValueError(f"{path}: unknown column(s) {unknown}; allowed: {list(allowed)}")
    return names


def read_record(path: str | Path) -> Response:
    """Reads a record CSV into a Response of kind ``"record"``; errors name the file, column and row."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"record file not found: {path}")
    if path.is_dir():
        raise ValueError(f"record file {path} is a directory")
    try:  # utf-8-sig: a byte-order mark (spreadsheet export) is not part of the first column's name
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError as e:
        raise ValueError(f"{path}: not a UTF-8 text file ({e.reason} at byte {e.start})") from None
    names = _columns(path, lines[0].strip() if lines else "")
    rows = [ln for ln in lines[1:] if ln.strip()]
    if not rows:
        raise ValueError(f"{path}: no data rows after the header")
    try:
        data = np.loadtxt(rows, delimiter=",", ndmin=2)
    except ValueError as e:
        raise ValueError(f"{path}: could not parse numbers: {e}") from None
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: {data.shape[1]} values per row but {len(names)} header columns")
    channels = {n: data[:, i].copy() for i, n in enumerate(names)}
    for n, v in channels.items():
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValueError(f"{path}: column {n!r} row {bad[0] + 2} is {v[bad[0]]} (must be finite)")
    uniform_dt(channels["time"], str(path))
    for n in ("flags", "internal_steps", "rhs_evals"):
        if n in channels:
            channels[n] = channels[n].astype(np.uint32 if n == "flags" else np.int64)
    return Response(channels, kind="record", path=path)


def write_record(path: str | Path, record: Response | Mapping[str, ArrayLike]) -> Path:
    """Writes every channel of a Response (or a dict of arrays) to a record CSV: ``record.to_csv(path)``."""
    if not isinstance(record, Response):
        if not isinstance(record, Mapping):
            raise ValueError(f"cannot write {path}: expected a Response or a dict of arrays, got "
                             f"{type(record).__name__}")
        if "time" not in record:
            raise ValueError(f"cannot write {path}: missing channel(s) ['time']")
        record = Response(record, kind="record")
    return record.to_csv(path)


__all__ = ["UNIT_SUFFIXED_COLUMNS", "Record", "read_record", "write_record"]
