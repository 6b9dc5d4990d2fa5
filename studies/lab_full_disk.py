"""``compare`` and ``identify`` on a full disk (docs/robustness.md, issue 26 defect 9): each
command's output set written into a fresh folder on a simulated disk that fills at 11 sizes
(nothing, 1 and 100 bytes, each eighth of the whole set, all but one byte; the
``FullDisk`` of tests/python/test_reliability3_lab.py).  Counts the sizes that leave a
partial set (some of the files) behind.

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python studies/lab_full_disk.py
"""

from __future__ import annotations

import builtins
import io
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))

from test_reliability3_lab import DT, FullDisk, _budgets, _files, noise_command  # noqa: E402

import servohydraulics as sh  # noqa: E402


def _install(disk: FullDisk) -> FullDisk:
    builtins.open = io.open = disk.open
    return disk


def main() -> None:
    real = builtins.open
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        sh.simulate(sh.zhao2003(), mode="displacement", command=noise_command(), dt=DT).to_csv(d / "rec.csv")
        writers = {"compare": sh.identification.compare(sh.read_record(d / "rec.csv"), sh.zhao2003(),
                                                        "displacement").write,
                   "identify": sh.identify([d / "rec.csv"], rig=sh.zhao2003(), fit=["K_v"], mode="displacement",
                                           max_nfev=2, progress=False).write}
        try:
            for name, write in writers.items():
                disk = _install(FullDisk(d, float("inf")))
                write(d / f"{name}_whole")
                budgets = _budgets(disk.written)
                partial = 0
                for b in budgets:
                    _install(FullDisk(d, b))
                    try:
                        write(d / f"{name}_{b}")
                    except OSError:
                        pass
                    partial += bool(_files(d / f"{name}_{b}"))
                print(f"{name}: {partial} of {len(budgets)} full-disk sizes leave a partial output set "
                      f"(the whole set: {disk.written:,} bytes)")
        finally:
            builtins.open = io.open = real


if __name__ == "__main__":
    main()
