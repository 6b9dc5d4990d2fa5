"""Delimited text records: an optional metadata block, a row of column names, rows of values.

The layouts read (docs/lab-records.md, "Record files"):

* a CSV with a header row (the project's own, spreadsheets' exports with a byte-order
  mark or quoted names);
* the delimiter is found from the header and the first and last rows: comma,
  semicolon, tab or whitespace (``delimiter=`` names it instead); a decimal comma is
  accepted where it cannot be a delimiter (semicolon, tab or whitespace files whose
  numbers all use the comma: a file mixing ``1,5`` and ``2.5`` is refused);
* a metadata block before the names (data-acquisition exports): leading ``key: value``
  (or ``key = value``) lines and comment lines (``#``, ``%``, ``//``), or the first
  ``header_lines - 1`` lines when ``header_lines`` is given; its keys are the record's
  metadata (a sample interval or rate, a sample count: ``layout.py`` checks them);
* no names at all (the first line is numbers): the columns are named ``1``, ``2``, ...
  and must be mapped (``--columns time=1,command=2,...``);
* rows whose trailing columns are free text the reader does not use (an ``Events``
  column that holds ``DAQ Start`` in one row, ``DAQ Pause, DAQ Stop`` in another and
  nothing elsewhere): the number of fields may vary beyond the last column used.
  Where every column is used, a row with another number of fields is an error.

NumPy only (``import servohydraulics`` reads records without SciPy).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: delimiter names -> the character (None: runs of whitespace)
DELIMITERS: dict[str, str | None] = {",": ",", "comma": ",", ";": ";", "semicolon": ";", "tab": "\t", "\t": "\t",
                                     "whitespace": None, "space": None, " ": None}
#: the sniffer's candidates, in order of preference on a tie
CANDIDATES: tuple[str | None, ...] = (",", ";", "\t", None)
COMMENTS = ("#", "%", "//")
#: a metadata line: a key without delimiters, then ':' or '=', then the value
_META = re.compile(r"^\s*([A-Za-z][^:=,;\t]*?)\s*[:=]\s*(.*?)\s*$")
_DECIMAL_COMMA = re.compile(r"^\s*[+-]?(\d+,\d*|,\d+)([eE][+-]?\d+)?\s*$")
_NUMBER = re.compile(r"^\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?\s*$")
#: rows the sniffer looks at (the first ones and the last ones)
SNIFF_HEAD, SNIFF_TAIL = 50, 5


def delimiter_name(d: str | None) -> str:
    return {",": "','", ";": "';'", "\t": "tab", None: "whitespace"}.get(d, repr(d))


def split(line: str, d: str | None) -> list[str]:
    return line.split() if d is None else line.split(d)


def _clean(name: str) -> str:
    return name.strip().strip('"').strip("'").strip()


@dataclass(eq=False)
class Table:
    """A delimited text file as read: names, rows split into fields, metadata."""

    path: Path
    header: list[str]  #: the column names (``1``, ``2``, ... when the file has none)
    rows: list[list[str]] = field(repr=False)  #: the data rows, split
    lines: np.ndarray = field(repr=False)  #: each row's line number in the file (1-based)
    metadata: dict = field(default_factory=dict)  #: the metadata block's ``key: value`` pairs
    delimiter: str | None = ","
    decimal: str = "."
    named: bool = True  #: the file has a row of column names

    def describe(self) -> str:
        """The header as read, for error messages."""
        what = "header" if self.named else "no header row; columns by number"
        return f"{what} {self.header} (delimiter {delimiter_name(self.delimiter)})"

    def check_rows(self, used_up_to: int) -> None:
        """ValueError naming the file and the line of a row too short for the columns used
        (``used_up_to``: the last column index read) or, when the last column is read, a row with
        another number of fields than the header (trailing free-text columns may vary)."""
        n_head = len(self.header)
        exact = used_up_to >= n_head - 1
        for k, r in enumerate(self.rows):
            if len(r) <= used_up_to or (exact and len(r) != n_head):
                raise ValueError(f"{self.path}: could not parse row {self.lines[k]}: {len(r)} field(s), the header "
                                 f"{n_head} (delimiter {delimiter_name(self.delimiter)}): a truncated row or "
                                 f"mixed delimiters? the row: {self.delimiter_join(r)[:80]!r}")

    def column(self, index: int, label: str) -> np.ndarray:
        """Column ``index`` as floats (a decimal comma turned into a point; rows checked by
        :meth:`check_rows` first); ValueError naming the file, ``label``, the line and the text of
        a cell that is not a number."""
        cells = [r[index] for r in self.rows]
        if self.decimal == ",":
            cells = [c.replace(",", ".") for c in cells]
        try:
            return np.array(cells, dtype=float)
        except ValueError:
            for k, c in enumerate(cells):
                try:
                    float(c)
                except ValueError:
                    raise ValueError(f"{self.path}: could not parse {label} row {self.lines[k]}: {c.strip()!r} is "
                                     "not a number") from None
            raise

    def delimiter_join(self, fields: list[str]) -> str:
        return (" " if self.delimiter is None else self.delimiter).join(fields)


def read_text(path: Path) -> str:
    """The file's text: UTF-8 (a byte-order mark dropped), else Windows-1252 (a lab PC's
    export); ValueError naming the file for a binary one."""
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        try:
            text = data.decode("cp1252")
        except UnicodeDecodeError:
            raise ValueError(f"{path}: not a text file ({e.reason} at byte {e.start})") from None
    if "\x00" in text[:4096]:
        raise ValueError(f"{path}: not a text file (NUL bytes: a binary file; .mat files need the .mat suffix)")
    return text


def _metadata(lines: list[str], start: int, header_lines: int | None) -> tuple[dict, int]:
    """(metadata, index of the names line): the given block, or the leading ``key: value`` and
    comment lines."""
    meta: dict[str, str] = {}
    if header_lines is not None:
        for i, ln in enumerate(lines[:max(header_lines - 1, 0)]):
            m = _META.match(ln)
            if m:
                meta[m.group(1)] = m.group(2)
            elif ln.strip() and not ln.lstrip().startswith(COMMENTS):
                meta[f"line {i + 1}"] = ln.strip()
        return meta, max(header_lines - 1, 0)
    i = start
    while i < len(lines):
        ln = lines[i]
        if not ln.strip() or ln.lstrip().startswith(COMMENTS):
            i += 1
            continue
        m = _META.match(ln)
        if not m or _is_numbers(ln):
            break
        meta[m.group(1)] = m.group(2)
        i += 1
    return meta, i


def _is_numbers(line: str) -> bool:
    for d in CANDIDATES:
        f = [c for c in split(line, d) if c.strip()]
        if f and all(_NUMBER.match(c) or _DECIMAL_COMMA.match(c) for c in f):
            return len(f) > 1 or d is None
    return False


def _counts(lines: list[str], d: str | None) -> list[int]:
    return [len(split(ln, d)) for ln in lines]


def sniff(path: Path, header: str, sample: list[tuple[int, str]]) -> str | None:
    """The delimiter that splits the header and the sampled rows into the same number (>= 2) of
    fields; one more or fewer is allowed in rows when no candidate agrees exactly (free-text
    trailing columns).  ValueError naming the file and the lines when none does."""
    best: tuple[int, int] | None = None
    choice: str | None = ","
    for rank, d in enumerate(CANDIDATES):
        hc = len(split(header, d))
        if hc < 2:
            continue
        counts = _counts([ln for _, ln in sample], d)
        if not counts:
            exact, near = True, True
        else:
            exact = all(c == hc for c in counts)
            near = sum(abs(c - hc) <= 1 and c >= 2 for c in counts) >= 0.9 * len(counts)
        if exact or near:
            key = (0 if exact else 1, rank)
            if best is None or key < best:
                best, choice = key, d
    if best is not None:
        return choice
    if all(len(split(header, d)) < 2 for d in CANDIDATES) and all(
            len(split(ln, d)) < 2 for _, ln in sample for d in CANDIDATES):
        return ","  # one column: nothing to tell apart (the column check names what is missing)
    hd = max(CANDIDATES, key=lambda d: len(split(header, d)))
    hc = len(split(header, hd))
    worst = next(((k, ln) for k, ln in sample if len(split(ln, hd)) != hc), sample[0] if sample else (0, ""))
    raise ValueError(f"{path}: mixed or unknown delimiters: the header {header.strip()[:80]!r} splits into {hc} "
                     f"field(s) by {delimiter_name(hd)} but row {worst[0]} {worst[1].strip()[:80]!r} into "
                     f"{len(split(worst[1], hd))}; give the delimiter (--delimiter ',', ';', tab or whitespace)")


def _decimal(path: Path, sample: list[tuple[int, str]], d: str | None, decimal: str) -> str:
    if decimal in (".", ","):
        if decimal == "," and d == ",":
            raise ValueError(f"{path}: invalid decimal = ',': the delimiter is ',' too")
        return decimal
    if d == ",":
        return "."
    comma = point = None
    for k, ln in sample:
        for c in split(ln, d):
            if comma is None and _DECIMAL_COMMA.match(c):
                comma = (k, c.strip())
            elif point is None and "." in c and _NUMBER.match(c):
                point = (k, c.strip())
    if comma and point:
        raise ValueError(f"{path}: mixed decimal marks: row {comma[0]} has {comma[1]!r} and row {point[0]} "
                         f"{point[1]!r}; give the decimal mark (decimal = ',' or '.' in a layout)")
    return "," if comma else "."


def read_table(path: Path, delimiter: str | None = "auto", decimal: str = "auto",
               header_lines: int | None = None) -> Table:
    """Reads a delimited text file (see the module docstring).  ``delimiter``: ``"auto"`` or a
    name of ``DELIMITERS``; ``decimal``: ``"auto"``, ``"."`` or ``","``; ``header_lines``: the
    lines up to and including the names (0: the file has no names; None: found)."""
    text = read_text(path)
    lines = text.splitlines()
    meta, i = _metadata(lines, 0, header_lines)
    while header_lines is None and i < len(lines) and not lines[i].strip():
        i += 1
    if i >= len(lines):  # an empty file (or only a header block): no columns, the check names them
        lines = lines + [""]
    named = header_lines != 0 and not (header_lines is None and _is_numbers(lines[i]))
    head = lines[i] if named else ""
    first = i + 1 if named else i
    data = [(k + 1, ln) for k, ln in enumerate(lines[first:], start=first) if ln.strip()]
    if delimiter is None or delimiter == "auto":
        sample = data[:SNIFF_HEAD] + data[max(SNIFF_HEAD, len(data) - SNIFF_TAIL):]
        d = sniff(path, head, sample) if named else sniff(path, data[0][1] if data else "", sample)
    else:
        if delimiter not in DELIMITERS:
            raise ValueError(f"{path}: invalid delimiter = {delimiter!r}: expected one of "
                             f"',', ';', 'tab', 'whitespace' or 'auto'")
        d = DELIMITERS[delimiter]
        sample = data[:SNIFF_HEAD]
    if decimal not in ("auto", ".", ","):
        raise ValueError(f"{path}: invalid decimal = {decimal!r}: expected '.', ',' or 'auto'")
    dec = _decimal(path, data[:SNIFF_HEAD] + data[-SNIFF_TAIL:], d, decimal)
    if named:
        header = [_clean(h) for h in split(head, d)]
    else:
        header = [str(k + 1) for k in range(len(split(data[0][1], d)) if data else 0)]
    rows = [split(ln, d) for _, ln in data]
    return Table(path=path, header=header, rows=rows, lines=np.array([k for k, _ in data], dtype=np.int64),
                 metadata=meta, delimiter=d, decimal=dec, named=named)


__all__ = ["CANDIDATES", "DELIMITERS", "Table", "delimiter_name", "read_table", "read_text", "sniff"]
