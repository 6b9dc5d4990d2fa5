"""Lab records as CSV: a header row, then one row per sample, SI units.

Required columns: ``time`` [s], ``command`` [m in displacement control, N in
force control], ``displacement`` [m], ``force`` [N].  Optional: any other
channel of a run (``channel_units("record")``: ``velocity`` [m/s],
``acceleration`` [m/s^2], ``pressure`` [Pa], ``spool`` [-], ``drive`` [V],
``flow`` [m^3/s], ``ground_acceleration`` [m/s^2], the EFT and RPsD channels,
``flags``...).  Time must be uniform and increasing.  The old column name
``ground_accel`` is read as ``ground_acceleration`` for one release.

Lab files that name their columns with a unit (``time_s``, ``command_m``,
``displacement_mm``, ``force_kN``, ``Force [kN]``) are read under the project's
names and converted to SI; other units, scales, column names, delimiters, header
blocks and MATLAB files: ``servohydraulics.readers`` (docs/lab-records.md).

A record is a :class:`~servohydraulics.response.Response` of kind ``"record"``;
``write_record(path, r)`` is ``r.to_csv(path)``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from numpy.typing import ArrayLike

from .response import Response

#: Deprecated name of a record: records are Responses of kind "record".
Record = Response


#: Unit-suffixed column names read as the project's channel names (any unit of the channel's
#: dimension is read now, ``readers.record``: ``displacement_mm``, ``force_kN``, ``Force [kN]``).
UNIT_SUFFIXED_COLUMNS = {"time_s": "time", "command_m": "command", "command_N": "command",
                         "displacement_m": "displacement", "force_N": "force"}


def read_record(path: str | Path, layout=None, *, columns: Mapping[str, str] | None = None,
                units: Mapping[str, str] | None = None, scale: Mapping[str, float] | None = None,
                delimiter: str | None = None, decimal: str | None = None, header_lines: int | None = None,
                offset_first_s: float | None = None) -> Response:
    """Reads a record file into a Response of kind ``"record"`` (SI units).

    Text (CSV, semicolon, tab or whitespace separated, a data-acquisition export with a
    header block) or MATLAB ``.mat`` (by the suffix); see docs/lab-records.md, "Record files".

    Args:
        path: the file.
        layout: a :class:`~servohydraulics.readers.Layout`, a layout TOML file or a dict of its fields.
        columns: channel -> the file's column (``{"command": "CHANNEL2"}``; .mat: a variable
            ``"u"``, ``"rec.u"``, ``"M.u"`` or ``"M(:,2)"``).
        units: channel -> unit of the file's values (``{"displacement": "mm", "time": "ms"}``).
        scale: channel -> factor (volts to the unit: ``{"force": 980.665}``).
        delimiter, decimal, header_lines: text files (default: found from the file).
        offset_first_s: subtract each channel's mean over the first seconds [s].

    ``Response.metadata`` says what was read (columns, units, scales, offsets, the header block).
    Errors name the file, the column (with the header read and the mapping tried) or the
    field, and the value.
    """
    from .readers import read

    return read(path, layout, columns=columns, units=units, scale=scale, delimiter=delimiter, decimal=decimal,
                header_lines=header_lines, offset_first_s=offset_first_s)


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
