"""The one place the evaluation scripts write their tables into a doc: between two markers."""

from __future__ import annotations

import os
import sys
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


#: The UTFSM MTS + MR damper records (../shared, or $SH_SHARED_DIR); never copied into the project.
UTFSM_DATA = (Path(os.environ.get("SH_SHARED_DIR", Path(__file__).resolve().parents[2] / "shared"))
              / "real-data" / "utfsm-mts-mrdamper")


def utfsm_start(data: str, names, out: str):
    """The start the UTFSM scripts share: the project's package imported from this tree, the named
    records of the folder `data` read and `out` created.  (sh, {name: Response}, out Path), or None
    with a message on stderr when the folder is not there."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
    import servohydraulics as sh

    folder = Path(data)
    if not folder.is_dir():
        print(f"UTFSM records not found in {folder}: see docs/lab-records.md", file=sys.stderr)
        return None
    records = {n: sh.read_record(folder / f"{n}.csv") for n in names}
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    return sh, records, out_dir
