"""The one place the evaluation scripts write their tables into a doc: between two markers."""

from __future__ import annotations

from pathlib import Path


def write_between(doc: Path, start: str, end: str, text: str) -> None:
    """Replaces what lies between the ``start`` and ``end`` markers of ``doc`` with ``text``
    (the markers stay); ValueError naming the doc and the marker when one is missing."""
    s = doc.read_text()
    for marker in (start, end):
        if marker not in s:
            raise ValueError(f"{doc}: marker {marker!r} not found")
    i, j = s.index(start) + len(start), s.index(end)
    doc.write_text(s[:i] + "\n" + text + "\n" + s[j:])
