"""Readers of lab record files: delimited text (CSV and its relatives, data-acquisition
exports with a header block), MATLAB ``.mat``, with units, scales and column mappings
(docs/lab-records.md, "Record files").

    rec = sh.read_record("run.txt", layout="daq.toml")                 # a layout file
    rec = sh.read_record("run.csv", units={"displacement": "mm", "force": "kN"})
    rec = sh.read_record("run.mat", columns={"command": "rec.u", "force": "rec.F"})
    rec.metadata        # what was read: columns, units, scales, offsets, header block

:func:`read` is ``sh.read_record``'s work; :class:`Layout` says how a lab's files are laid out.
NumPy only at import (SciPy loads for a .mat file).
"""

from __future__ import annotations

from pathlib import Path

from ..response import Response
from .layout import Layout, add_arguments, as_layout, from_flags, layout_of, load_layout
from .units import UNITS

#: file suffixes read as MATLAB files
MAT_SUFFIXES = (".mat",)


def read(path: str | Path, layout: Layout | str | Path | dict | None = None, **changes) -> Response:
    """Reads a record file (text or .mat, by ``layout.format`` or the suffix) into a Response of
    kind ``"record"``; ``changes`` are :class:`Layout` fields overriding the layout's.  Errors
    (ValueError, FileNotFoundError) name the file, the column or field and the value."""
    path = Path(path)
    lay = as_layout(layout, **changes)
    if not path.exists():
        raise FileNotFoundError(2, f"record file not found: {path}", str(path))
    if path.is_dir():
        raise ValueError(f"record file {path} is a directory")
    mat = lay.format == "mat" or (lay.format == "auto" and path.suffix.lower() in MAT_SUFFIXES)
    from .record import assemble

    if mat:
        from .matfile import read_mat

        return assemble(path, read_mat(path), lay, text=False)
    from .text import read_table

    table = read_table(path, lay.delimiter, lay.decimal, lay.header_lines)
    return assemble(path, table, lay, text=True)


__all__ = ["MAT_SUFFIXES", "UNITS", "Layout", "add_arguments", "as_layout", "from_flags", "layout_of", "load_layout",
           "read"]
