"""A record file read into a :class:`~servohydraulics.response.Response`: the file's
columns (text, :mod:`.text`) or variables (.mat, :mod:`.matfile`) matched to the
project's channels, scaled to SI, checked against the header's own claims
(sample count, interval, rate, time stamps) and, if asked, zeroed on the first
seconds.

Matching: a column the layout names (``columns``) is that channel; any other column
whose name is a channel's (case aside), with or without a unit (``force``, ``force_N``,
``force_kN``, ``Force [kN]``, ``displacement (mm)``), is that channel in that unit.  Where
the user names no columns, any other column is an error (a misspelt channel is not
dropped silently); where the user names some, the others are ignored and listed in
``Response.metadata["ignored"]``.  Every error about columns shows the header read and
the mapping tried.
"""

from __future__ import annotations

import datetime as _dt
import math
import warnings
from pathlib import Path

import numpy as np

from ..response import DEPRECATED_COLUMNS, REQUIRED, Response, channel_units
from ..timegrid import uniform_dt
from .layout import Layout
from .units import SAMPLES, header_unit, unit_factor

#: keys of a header block read as the sample count, interval [s] and rate [Hz] (case aside)
COUNT_KEYS = ("sample count", "samples", "number of samples", "numsamples", "n samples")
INTERVAL_KEYS = ("sampling interval", "sample interval", "sampling period", "sample period", "dt", "delta t")
RATE_KEYS = ("sampling rate", "sample rate", "sampling frequency", "sample frequency", "fs")
#: agreement required between the header's interval and rate, and the time column [relative]
INTERVAL_RTOL = 1e-6
#: time stamps checked (at most this many, evenly spread) and their tolerance: the stamps'
#: resolution (1 ms) twice, plus 0.1 % of the span (a DAQ clock against the wall clock)
STAMPS_CHECKED, STAMP_RESOLUTION, STAMP_RTOL = 1000, 1e-3, 1e-3
_COUNTS = ("flags", "internal_steps", "rhs_evals")


def _meta_value(meta: dict, keys: tuple[str, ...]) -> tuple[str, str] | None:
    low = {k.strip().lower(): k for k in meta}
    for k in keys:
        if k in low:
            return low[k], meta[low[k]]
    return None


def _meta_number(path: Path, meta: dict, key: str) -> float:
    text = str(meta[key]).strip().split()[0] if str(meta[key]).strip() else ""
    try:
        return float(text.replace(",", "."))
    except ValueError:
        raise ValueError(f"{path}: header {key!r} = {meta[key]!r}: not a number") from None


def _match(name: str, allowed: dict) -> tuple[str, str | None] | None:
    """(channel, unit or None) a column name stands for, or None."""
    low = {c.lower(): c for c in allowed}
    low.update({k.lower(): v for k, v in DEPRECATED_COLUMNS.items()})
    leaf = name.rsplit(".", 1)[-1]
    base, unit = header_unit(leaf)
    if base.lower() in low:
        return low[base.lower()], unit
    if unit is None and "_" in base:
        stem, suffix = base.rsplit("_", 1)
        if stem.lower() in low:
            ch = low[stem.lower()]
            try:
                unit_factor(ch, allowed.get(ch, "m or N"), suffix, "")
            except ValueError:
                return None
            return ch, suffix
    return None


class _Columns:
    """The channel -> source column resolution of one file."""

    def __init__(self, path: Path, src, layout: Layout, text: bool):
        self.path, self.src, self.layout, self.text = path, src, layout, text
        self.header = list(src.header)
        self.allowed = channel_units("record")
        self.chosen: dict[str, str] = {}  # channel -> source name
        self.units: dict[str, str] = {}  # channel -> unit (from the header or the layout)
        self.ignored: list[str] = []

    def tried(self) -> str:
        return f"the {self.src.describe()}; the mapping tried {self.chosen}"

    def _find(self, name: str) -> str | None:
        if name in self.header or (not self.text and self.src.get(name) is not None):
            return name
        folded = [h for h in self.header if h.lower() == name.lower()]
        if len(folded) == 1:
            return folded[0]
        if self.text and name.isdigit() and 1 <= int(name) <= len(self.header):
            return self.header[int(name) - 1]
        return None

    def resolve(self) -> None:
        lay = self.layout
        for ch, name in lay.columns.items():
            found = self._find(name)
            if found is None:
                self.chosen[ch] = name
                raise ValueError(f"{self.path}: {lay.name('columns')} {ch}={name!r} names no column: "
                                 + self.tried())
            self.chosen[ch] = found
        taken = set(self.chosen.values())
        seen: dict[str, str] = {}
        unknown = []
        for i, h in enumerate(self.header):
            if h in taken:
                continue
            m = _match(h, self.allowed)
            if m is None or m[0] in lay.columns:
                (self.ignored if (lay.mapped or not self.text or m is not None) else unknown).append(h)
                continue
            ch, unit = m
            if ch in seen:
                j = self.header.index(seen[ch])
                where = f"columns {j + 1} and {i + 1}" if self.text else f"{seen[ch]} and {h}"
                raise ValueError(f"{self.path}: column {ch!r} appears twice in the header ({where}); "
                                 f"name the one to read with --columns {ch}=NAME")
            if h in DEPRECATED_COLUMNS:
                warnings.warn(f"{self.path}: column {h!r} is deprecated; name it {DEPRECATED_COLUMNS[h]!r}",
                              DeprecationWarning, stacklevel=5)
            seen[ch] = h
            self.chosen[ch] = h
            if unit is not None:
                self.units[ch] = unit
        self.units.update(lay.units)
        missing = [c for c in REQUIRED if c not in self.chosen and not (c == "time" and self.has_interval())]
        if missing:
            raise ValueError(f"{self.path}: missing column(s) {missing}: " + self.tried()
                             + f"; name them with --columns {missing[0]}=NAME (a record needs {list(REQUIRED)})")
        if unknown:
            raise ValueError(f"{self.path}: unknown column(s) {unknown}: {self.tried()}; allowed: "
                             f"{list(self.allowed)}; read only the columns you name with --columns NAME=HEADER")

    def has_interval(self) -> bool:
        return self.interval() is not None

    def interval(self) -> tuple[float, str] | None:
        """(sample interval [s], where it came from) from the layout, the header block or a .mat scalar."""
        si, meta = self.layout.sample_interval, getattr(self.src, "metadata", {})
        if isinstance(si, (int, float)):
            return float(si), self.layout.name("sample_interval")
        if isinstance(si, str):
            if self.text:
                if si not in meta:
                    raise ValueError(f"{self.path}: {self.layout.name('sample_interval')} = {si!r} is not a key of "
                                     f"the header block: {list(meta)}")
                return _meta_number(self.path, meta, si), f"header {si!r}"
            if si not in self.src.scalars:
                raise ValueError(f"{self.path}: {self.layout.name('sample_interval')} = {si!r} is not a scalar of "
                                 f"the file: {self.src.describe()}")
            return self.src.scalars[si], f"variable {si!r}"
        if self.text:
            iv, rt = _meta_value(meta, INTERVAL_KEYS), _meta_value(meta, RATE_KEYS)
            if iv is not None:
                return _meta_number(self.path, meta, iv[0]), f"header {iv[0]!r}"
            if rt is not None:
                return 1.0 / _meta_number(self.path, meta, rt[0]), f"header {rt[0]!r} (1/rate)"
            return None
        from .matfile import sample_interval

        v = sample_interval(self.src)
        return None if v is None else (v, "a scalar of the file")

    def raw(self, ch: str) -> np.ndarray:
        name = self.chosen[ch]
        if self.text:
            return self.src.column(self.header.index(name), f"column {ch!r} (header {name!r})")
        v = self.src.get(name)
        return np.asarray(v, dtype=float)


def _factor(cols: _Columns, ch: str) -> tuple[float, str]:
    """(factor to SI, unit description) of a channel: scale x unit factor."""
    lay, si = cols.layout, cols.allowed.get(ch, "-")
    unit = cols.units.get(ch)
    where = f"{cols.path}: {lay.name('units')}" if ch in lay.units else f"{cols.path}: header {cols.chosen.get(ch)!r}"
    f, dim = (1.0, si) if unit is None else unit_factor(ch, si, unit, where)
    s = float(lay.scale.get(ch, 1.0))
    return f * s if dim != SAMPLES else s, (unit or si) if dim != SAMPLES else SAMPLES


def _check_count(cols: _Columns, n: int) -> None:
    meta = getattr(cols.src, "metadata", {})
    key = cols.layout.sample_count
    if key is not None:
        if key not in meta:
            raise ValueError(f"{cols.path}: {cols.layout.name('sample_count')} = {key!r} is not a key of the "
                             f"header block: {list(meta)}")
        found = (key, meta[key])
    else:
        found = _meta_value(meta, COUNT_KEYS)
    if found is None:
        return
    count = _meta_number(cols.path, meta, found[0])
    if count != n:
        why = "the file is truncated or the header is wrong" if n < count else "the header is wrong"
        raise ValueError(f"{cols.path}: invalid header {found[0]!r} = {found[1]!r}: the file has {n} data rows "
                         f"({why})")


def _check_rate(cols: _Columns) -> None:
    meta = getattr(cols.src, "metadata", {}) if cols.text else {}
    iv, rt = _meta_value(meta, INTERVAL_KEYS), _meta_value(meta, RATE_KEYS)
    if iv and rt:
        a, b = _meta_number(cols.path, meta, iv[0]), _meta_number(cols.path, meta, rt[0])
        if not (b > 0 and abs(a * b - 1.0) <= 1e-6):
            raise ValueError(f"{cols.path}: invalid header {iv[0]!r} = {iv[1]!r}: the header's {rt[0]!r} is "
                             f"{rt[1]!r} (interval x rate = {a * b:.6g}, not 1)")


def _check_stamps(cols: _Columns, dt: float) -> None:
    """The time stamps against the sample interval: at most ``STAMPS_CHECKED`` of them, evenly spread."""
    lay = cols.layout
    name = cols._find(lay.timestamps) if cols.text else None
    if name is None:
        raise ValueError(f"{cols.path}: {lay.name('timestamps')} = {lay.timestamps!r} names no column: "
                         + cols.tried())
    j = cols.header.index(name)
    rows, lines = cols.src.rows, cols.src.lines
    idx = np.unique(np.linspace(0, len(rows) - 1, min(STAMPS_CHECKED, len(rows))).astype(int))
    stamps = []
    for k in idx:
        text = rows[k][j].strip()
        try:
            stamps.append(_dt.datetime.strptime(text, lay.timestamp_format).timestamp())
        except ValueError:
            raise ValueError(f"{cols.path}: time stamp {name!r} row {lines[k]} is {text!r}: does not match "
                             f"{lay.name('timestamp_format')} {lay.timestamp_format!r}") from None
    s = np.asarray(stamps)
    span, expect = np.diff(s), np.diff(idx) * dt
    bad = np.flatnonzero(np.abs(span - expect) > 2 * STAMP_RESOLUTION + STAMP_RTOL * expect)
    if bad.size:
        b = int(bad[0])
        raise ValueError(f"{cols.path}: time stamps {name!r} disagree with the sample interval {dt:g} s: rows "
                         f"{lines[idx[b]]} to {lines[idx[b + 1]]} are {span[b]:.6g} s apart on the stamps and "
                         f"{expect[b]:.6g} s by the interval (samples missing, or a wrong interval)")


def assemble(path: Path, src, layout: Layout, text: bool) -> Response:
    """The record of a read source (a text ``Table`` or a ``MatSource``); see the module docstring."""
    cols = _Columns(path, src, layout, text)
    cols.resolve()
    if text:
        used = [cols.header.index(n) for n in cols.chosen.values()]
        src.check_rows(max(used))
    data, units_used, scales = {}, {}, {}
    n = None
    for ch in cols.chosen:
        v = cols.raw(ch)
        if n is not None and v.size != n:
            raise ValueError(f"{path}: column {ch!r} ({cols.chosen[ch]!r}) has {v.size} samples, "
                             f"{next(iter(cols.chosen))!r} has {n}")
        n = v.size
        data[ch] = v
    if n is None or n == 0:
        raise ValueError(f"{path}: no data rows after the header")
    for ch, v in data.items():
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            row = f"row {src.lines[bad[0]]}" if text else f"sample {bad[0] + 1}"
            raise ValueError(f"{path}: column {ch!r} {row} is {v[bad[0]]} (must be finite)")
    _check_count(cols, n)
    if text:
        _check_rate(cols)
    iv = cols.interval()
    for ch in list(data):
        f, unit = _factor(cols, ch)
        if unit == SAMPLES:
            if iv is None:
                raise ValueError(f"{path}: time in samples ({cols.chosen['time']!r}) needs the sample interval: "
                                 "give sample_interval in the layout (a number or a header key)")
            k = data[ch]
            if not np.all(np.diff(k) == 1):
                i = int(np.flatnonzero(np.diff(k) != 1)[0])
                raise ValueError(f"{path}: sample numbers {cols.chosen['time']!r} are not consecutive: "
                                 f"{k[i]:g} then {k[i + 1]:g} (samples missing?)")
            data[ch] = (k - k[0]) * iv[0] * f
        elif f != 1.0:
            data[ch] = data[ch] * f
        units_used[ch], scales[ch] = unit, f
    if "time" not in data:
        data = {"time": np.arange(n) * iv[0], **data}
        units_used["time"], scales["time"] = f"{iv[0]:g} s per sample ({iv[1]})", iv[0]
    dt = uniform_dt(data["time"], str(path))
    if iv is not None and "time" in cols.chosen and cols.units.get("time") != SAMPLES:
        if abs(dt - iv[0]) > INTERVAL_RTOL * iv[0]:
            raise ValueError(f"{path}: invalid sample interval = {iv[0]!r} s ({iv[1]}): the time column "
                             f"{cols.chosen['time']!r} steps by {dt:.9g} s")
    if layout.timestamps is not None:
        _check_stamps(cols, dt)
    offsets = _offsets(path, data, layout, dt)
    for c in _COUNTS:
        if c in data:
            data[c] = data[c].astype(np.uint32 if c == "flags" else np.int64)
    meta = {"format": "text" if text else f"mat v{src.version}", "columns": dict(cols.chosen),
            "units": units_used, "scales": scales, "header": list(cols.header)[:200],
            "metadata": dict(getattr(src, "metadata", {}) or {}) if text else dict(src.scalars),
            "ignored": cols.ignored, "offsets": offsets}
    if text:
        meta["delimiter"], meta["decimal"] = src.delimiter if src.delimiter is not None else "whitespace", src.decimal
    ordered = {"time": data.pop("time"), **data}
    return Response(ordered, kind="record", path=path, metadata=meta)


def _offsets(path: Path, data: dict, layout: Layout, dt: float) -> dict:
    """Subtracts each channel's mean over the first ``offset_first_s`` seconds; returns the offsets [SI]."""
    s = layout.offset_first_s
    if not s:
        return {}
    t = data["time"]
    m = int(np.searchsorted(t - t[0], s - 0.5 * dt))
    if m < 1 or m >= t.size:
        raise ValueError(f"{path}: invalid {layout.name('offset_first_s')} = {s!r}: the record is "
                         f"{t[-1] - t[0] + dt:.6g} s long ({t.size} samples)")
    chans = layout.offset_channels or [c for c in data if c != "time" and c not in _COUNTS]
    out = {}
    for c in chans:
        if c not in data:
            raise ValueError(f"{path}: invalid {layout.name('offset_channels')}: {c!r} is not read from this file "
                             f"(read: {list(data)})")
        off = float(np.mean(data[c][:m]))
        data[c] = data[c] - off
        out[c] = off
    if not all(math.isfinite(v) for v in out.values()):  # pragma: no cover - the values are finite
        raise ValueError(f"{path}: non-finite offset")
    return out


__all__ = ["COUNT_KEYS", "INTERVAL_KEYS", "RATE_KEYS", "assemble"]
