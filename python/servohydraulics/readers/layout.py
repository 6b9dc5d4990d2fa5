"""How to read a lab's record files: :class:`Layout`, from a small TOML file, the command
line's flags or keyword arguments.

A layout file (every key optional; docs/lab-records.md, "Record files")::

    # the UTFSM DAQ export (../shared/real-data/utfsm-mts-mrdamper/README.md)
    header_lines = 7                      # lines up to and including the column names
    delimiter = ","                       # "auto" (default), ",", ";", "tab", "whitespace"
    decimal = "."                         # "auto" (default), "." or ","
    sample_interval = "Sampling Interval" # [s]: a number, or a key of the header block
    sample_count = "Sample Count"         # a header key: the file must have this many rows
    timestamps = "Date/Time"              # a column of wall-clock stamps, checked against the interval
    timestamp_format = "%m/%d/%Y %I:%M:%S.%f %p"
    offset_first_s = 1.0                  # subtract each channel's mean over its first second

    [columns]                             # channel = the file's column (or a .mat variable)
    time = "Sample Number"
    command = "CHANNEL2"
    displacement = "CHANNEL0"
    force = "CHANNEL1"

    [units]                               # channel = the unit of the file's values
    time = "samples"                      # sample numbers times the sample interval

    [scale]                               # channel = factor to the unit (V -> m, V -> N)
    command = 0.01
    displacement = 0.01
    force = 9806.65

The value in SI is file value x scale x unit factor (``--scale force=0.980665 --units
force=kN``: a channel in volts at 0.980665 kN/V).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .units import parse_assignments, parse_scales

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

FORMATS = ("auto", "text", "mat")


@dataclass(frozen=True)
class Layout:
    """How a record file is read (every field optional; see the module docstring).

    Attributes:
        columns: channel -> the file's column name (a text file's header, a .mat variable
            ``v``, ``s.field``, ``M.name`` or ``M(:,k)``, or a column number ``3`` of a file
            without names).
        units: channel -> unit of the file's values (``mm``, ``kN``, ``ms``, ``samples``...).
        scale: channel -> factor the file's values are multiplied by (V -> the unit).
        delimiter, decimal: text files (``"auto"``: found from the file).
        header_lines: lines up to and including the column names (0: none; None: found).
        sample_interval: [s], or the name of a header key (or .mat scalar) that holds it.
        sample_count: a header key whose value the number of rows must equal.
        timestamps, timestamp_format: a column of wall-clock stamps (``datetime.strptime``
            format), checked against the sample interval.
        offset_first_s: [s] subtract each channel's mean over the record's first seconds.
        offset_channels: the channels the offset rule applies to (None: every channel read
            but time).
        format: ``"auto"`` (by the suffix: ``.mat`` or text), ``"text"`` or ``"mat"``.
        source: the layout file it came from (errors name it).
    """

    columns: Mapping[str, str] = field(default_factory=dict)
    units: Mapping[str, str] = field(default_factory=dict)
    scale: Mapping[str, float] = field(default_factory=dict)
    delimiter: str = "auto"
    decimal: str = "auto"
    header_lines: int | None = None
    sample_interval: float | str | None = None
    sample_count: str | None = None
    timestamps: str | None = None
    timestamp_format: str = "%m/%d/%Y %I:%M:%S.%f %p"
    offset_first_s: float = 0.0
    offset_channels: tuple[str, ...] | None = None
    format: str = "auto"
    source: str | None = None

    @property
    def mapped(self) -> bool:
        """The user named columns: columns the layout does not use are ignored, not refused."""
        return bool(self.columns)

    def where(self, what: str) -> str:
        """A message about the layout, prefixed with the layout file when it came from one."""
        return f"{self.source}: {what}" if self.source else what

    def name(self, key: str) -> str:
        """A field's name for a message about a record: ``key``, with the layout file it came from."""
        return f"{key} (layout {self.source})" if self.source else key

    def merged(self, **changes: Any) -> Layout:
        """This layout with the given fields replaced (None leaves a field as it is; the
        mappings are merged, a change's entry winning)."""
        out = {}
        for k, v in changes.items():
            if v is None:
                continue
            if k in ("columns", "units", "scale"):
                v = {**getattr(self, k), **dict(v)}
            out[k] = v
        return check_layout(dataclasses.replace(self, **out)) if out else self


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def check_layout(lay: Layout) -> Layout:
    """``lay`` with its values checked; ValueError naming the field (and the layout file) and the value."""
    from ..response import channel_units
    from .text import DELIMITERS

    allowed = channel_units("record")
    for what, mapping in (("columns", lay.columns), ("units", lay.units), ("scale", lay.scale)):
        if not isinstance(mapping, Mapping):
            raise ValueError(lay.where(f"invalid {what} = {mapping!r}: expected a table of channel = value"))
        for ch, v in mapping.items():
            if ch not in allowed:
                raise ValueError(lay.where(f"invalid {what} channel = {ch!r}: not a record channel; channels: "
                                           f"{', '.join(allowed)}"))
            if what != "scale" and (not isinstance(v, str) or not v.strip()):
                raise ValueError(lay.where(f"invalid {what} {ch} = {v!r}: expected a name"))
    try:
        parse_scales(dict(lay.scale), "scale")
    except ValueError as e:
        raise ValueError(lay.where(str(e))) from None
    if lay.delimiter != "auto" and lay.delimiter not in DELIMITERS:
        raise ValueError(lay.where(f"invalid delimiter = {lay.delimiter!r}: expected ',', ';', 'tab', 'whitespace' "
                                   "or 'auto'"))
    if lay.decimal not in ("auto", ".", ","):
        raise ValueError(lay.where(f"invalid decimal = {lay.decimal!r}: expected '.', ',' or 'auto'"))
    if lay.header_lines is not None and (not isinstance(lay.header_lines, int) or isinstance(lay.header_lines, bool)
                                         or lay.header_lines < 0):
        raise ValueError(lay.where(f"invalid header_lines = {lay.header_lines!r}: expected an integer >= 0"))
    si = lay.sample_interval
    if si is not None and not (isinstance(si, str) and si.strip()) and not (_is_number(si) and math.isfinite(si)
                                                                           and si > 0):
        raise ValueError(lay.where(f"invalid sample_interval = {si!r}: a number of seconds > 0 or a header key"))
    for k in ("sample_count", "timestamps"):
        v = getattr(lay, k)
        if v is not None and not (isinstance(v, str) and v.strip()):
            raise ValueError(lay.where(f"invalid {k} = {v!r}: expected a name"))
    if not isinstance(lay.timestamp_format, str) or "%" not in lay.timestamp_format:
        raise ValueError(lay.where(f"invalid timestamp_format = {lay.timestamp_format!r}: a strptime format"))
    o = lay.offset_first_s
    if not (_is_number(o) and math.isfinite(o) and o >= 0):
        raise ValueError(lay.where(f"invalid offset_first_s = {o!r}: a number of seconds >= 0"))
    if lay.offset_channels is not None:
        bad = [c for c in lay.offset_channels if c not in allowed or c == "time"]
        if bad:
            raise ValueError(lay.where(f"invalid offset_channels = {list(lay.offset_channels)!r}: {bad[0]!r} is "
                                       "not a record channel other than time"))
    if lay.format not in FORMATS:
        raise ValueError(lay.where(f"invalid format = {lay.format!r}: expected one of {list(FORMATS)}"))
    return lay


_FIELDS = {f.name for f in dataclasses.fields(Layout)} - {"source"}


def load_layout(path: str | Path) -> Layout:
    """A layout TOML file (see the module docstring); ValueError naming the file and the key."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(2, f"layout file not found: {path}", str(path))
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8-sig"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: not a valid TOML layout ({e})") from None
    unknown = sorted(set(data) - _FIELDS)
    if unknown:
        raise ValueError(f"{path}: unknown key(s) {unknown}; a layout has {sorted(_FIELDS)}")
    if "offset_channels" in data:
        oc = data["offset_channels"]
        if not isinstance(oc, list) or not all(isinstance(c, str) for c in oc):
            raise ValueError(f"{path}: invalid offset_channels = {oc!r}: expected a list of channel names")
        data["offset_channels"] = tuple(oc)
    return check_layout(Layout(**data, source=str(path)))


def as_layout(layout: Layout | str | Path | Mapping | None = None, **changes: Any) -> Layout:
    """A Layout from a Layout, a layout file's path, a dict of its fields or None (the default),
    with ``changes`` (keyword arguments of ``read_record``: None leaves a field alone)."""
    if layout is None:
        base = Layout()
    elif isinstance(layout, Layout):
        base = layout
    elif isinstance(layout, (str, Path)):
        base = load_layout(layout)
    elif isinstance(layout, Mapping):
        unknown = sorted(set(layout) - _FIELDS)
        if unknown:
            raise ValueError(f"invalid layout keys {unknown}: a layout has {sorted(_FIELDS)}")
        base = check_layout(Layout(**layout))
    else:
        raise ValueError(f"invalid layout = {layout!r}: expected a Layout, a layout file or a dict")
    return base.merged(**changes)


def from_flags(layout: str | None = None, columns=None, units=None, scale=None, delimiter: str | None = None,
               header_lines: int | None = None, offset_first_s: float | None = None) -> Layout:
    """The Layout of the command line's record flags (``--layout``, ``--columns``, ``--units``,
    ``--scale``, ``--delimiter``, ``--header-lines``, ``--offset-first``): the flags win over the
    layout file; errors name the flag and its value."""
    cols = parse_assignments(columns, "--columns") or None
    unit = parse_assignments(units, "--units") or None
    scl = parse_scales(scale, "--scale") or None
    if header_lines is not None and header_lines < 0:
        raise ValueError(f"invalid --header-lines = {header_lines}: expected an integer >= 0")
    if offset_first_s is not None and not (math.isfinite(offset_first_s) and offset_first_s >= 0):
        raise ValueError(f"invalid --offset-first = {offset_first_s!r}: a number of seconds >= 0")
    base = load_layout(layout) if layout else Layout()
    try:
        return base.merged(columns=cols, units=unit, scale=scl, delimiter=delimiter, header_lines=header_lines,
                           offset_first_s=offset_first_s)
    except ValueError as e:  # a flag's channel or value: name the flag
        text = str(e)
        for key, flag in (("columns", "--columns"), ("units", "--units"), ("scale", "--scale")):
            text = text.replace(f"invalid {key} ", f"invalid {flag} ", 1) if text.startswith(f"invalid {key} ") \
                else text
        raise ValueError(text) from None


def add_arguments(p) -> None:
    """The record flags of ``compare``, ``identify`` and ``diagnose`` (docs/lab-records.md)."""
    g = p.add_argument_group("reading the records (docs/lab-records.md, 'Record files')")
    g.add_argument("--layout", default=None, metavar="LAYOUT.toml",
                   help="a layout file: columns, units, scales, header lines, sample interval, offset rule")
    g.add_argument("--columns", action="append", default=None, metavar="NAME=HEADER[,...]",
                   help="which column holds a channel, e.g. command=CHANNEL2,force=F_kN (a .mat variable: "
                        "force=rec.F or M(:,3))")
    g.add_argument("--units", action="append", default=None, metavar="NAME=UNIT[,...]",
                   help="units of the file's values, e.g. displacement=mm,force=kN,time=ms")
    g.add_argument("--scale", action="append", default=None, metavar="NAME=FACTOR[,...]",
                   help="multiply a channel by FACTOR (volts to the unit), e.g. force=980.665")
    g.add_argument("--delimiter", default=None, choices=[",", ";", "tab", "whitespace", "auto"],
                   help="column delimiter of text records (default: found from the file)")
    g.add_argument("--header-lines", type=int, default=None, metavar="N",
                   help="lines up to and including the column names (default: found; 0: no names)")
    g.add_argument("--offset-first", type=float, default=None, metavar="SECONDS",
                   help="subtract each channel's mean over the record's first SECONDS (the actuator at rest)")


def layout_of(args) -> Layout:
    """The Layout of parsed record flags (:func:`add_arguments`)."""
    return from_flags(args.layout, args.columns, args.units, args.scale, args.delimiter, args.header_lines,
                      args.offset_first)


__all__ = ["FORMATS", "Layout", "add_arguments", "as_layout", "check_layout", "from_flags", "layout_of",
           "load_layout"]
