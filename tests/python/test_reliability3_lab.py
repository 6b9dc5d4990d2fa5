"""Reproducers of issue 26 ("Reliability 3") on ``compare`` and ``identify``:
output sets on a full disk (defect 9), user mistakes named (defect 10), the
run's warnings surfaced (defect 11)."""

from __future__ import annotations

import builtins
import errno
import io
from pathlib import Path

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.cli import main

DT = 2e-3


def _cli(capsys, *argv) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def noise_command(n: int = 1000, scale: float = 1e-3, seed: int = 7) -> np.ndarray:
    """Band-limited noise (0-20 Hz at DT): a stationary command with a coherent H1."""
    from scipy import signal

    b, a = signal.butter(2, 20.0 * 2 * DT)
    u = signal.lfilter(b, a, np.random.default_rng(seed).standard_normal(n))
    return scale * u / np.std(u)


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A record the preset simulated (displacement control) and the preset's rig file."""
    d = tmp_path_factory.mktemp("lab")
    res = sh.simulate(sh.zhao2003(), mode="displacement", command=noise_command(), dt=DT)
    res.to_csv(d / "rec.csv")
    sh.save_rig(sh.zhao2003(), d / "rig.toml")
    return d / "rec.csv", d / "rig.toml"


# ----------------------------------------------------------------------------- 9: a full disk

_OPEN = builtins.open  #: the real one (a FullDisk installed later must not wrap an earlier one)


class FullDisk:
    """Files opened for writing under ``root`` share ``budget`` bytes; the write that passes it
    writes what still fits and raises ENOSPC, as a full file system does."""

    def __init__(self, root: Path, budget: float):
        self.root, self.left, self.written = str(root), budget, 0

    def open(self, file, mode="r", *args, **kwargs):
        f = _OPEN(file, mode, *args, **kwargs)
        if any(c in mode for c in "wax+") and str(file).startswith(self.root):
            return _Limited(f, self)
        return f


class _Limited:
    def __init__(self, f, disk: FullDisk):
        self._f, self._disk = f, disk

    def write(self, data):
        n = len(data.encode() if isinstance(data, str) else memoryview(data).cast("B"))
        if n > self._disk.left:
            fits = int(self._disk.left)
            self._f.write(data[:fits])
            self._disk.left = 0
            raise OSError(errno.ENOSPC, "No space left on device")
        self._disk.left -= n
        self._disk.written += n
        return self._f.write(data)

    def __getattr__(self, name):
        return getattr(self._f, name)

    def __iter__(self):
        return iter(self._f)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return self._f.__exit__(*exc)


@pytest.fixture
def full_disk(monkeypatch):
    def install(root: Path, budget: float) -> FullDisk:
        disk = FullDisk(root, budget)
        monkeypatch.setattr(builtins, "open", disk.open)
        monkeypatch.setattr(io, "open", disk.open)
        return disk

    return install


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())} if folder.is_dir() else {}


def _budgets(total: int) -> list[int]:
    """Sizes at which the disk fills: nothing, a few bytes, each eighth of the set, all but one byte."""
    return sorted({0, 1, 100, *(total * k // 8 for k in range(1, 8)), total - 1})


def _fails_whole_or_not_at_all(write, folder: Path, full_disk, expected: tuple[str, ...]) -> None:
    disk = full_disk(folder.parent, float("inf"))
    write(folder)
    total, complete = disk.written, _files(folder)
    assert set(expected) <= set(complete)
    for budget in _budgets(total):
        full_disk(folder.parent, budget)
        with pytest.raises(OSError, match=r"cannot write .*: \[Errno 28\] No space left on device"):
            write(folder)
        assert _files(folder) == complete, f"the disk full at {budget} of {total} bytes changed the set"
        fresh = folder.with_name(f"{folder.name}_new_{budget}")
        full_disk(folder.parent, budget)
        with pytest.raises(OSError, match=r"No space left on device"):
            write(fresh)
        assert _files(fresh) == {}, f"the disk full at {budget} of {total} bytes left {list(_files(fresh))}"


def test_compare_on_a_full_disk_writes_all_or_nothing(lab, tmp_path, full_disk):
    rec, rig = lab
    c = sh.identification.compare(sh.read_record(rec), sh.load_rig(rig), "displacement")
    _fails_whole_or_not_at_all(c.write, tmp_path / "out", full_disk, ("comparison.json", "overlay.png", "frf.png"))


def test_identify_on_a_full_disk_writes_all_or_nothing(lab, tmp_path, full_disk):
    rec, rig = lab
    ident = sh.identify([rec], rig=rig, fit=["K_v"], mode="displacement", max_nfev=2, progress=False)
    _fails_whole_or_not_at_all(ident.write, tmp_path / "out", full_disk,
                               ("rig_identified.toml", "identification.json", "report.md", "overlay_rec.png",
                                "frf_rec.png"))


@pytest.mark.parametrize("command", ["compare", "identify"])
def test_cli_on_a_full_disk_is_one_line_and_no_file(lab, tmp_path, full_disk, capsys, command):
    rec, rig = lab
    out = tmp_path / "out"
    full_disk(tmp_path, 5000)
    extra = ["--quiet", "--fit=K_v", "--max-nfev=2"] if command == "identify" else []
    code, _, err = _cli(capsys, command, rec, "--rig", rig, "--mode", "displacement", "--out", out, *extra)
    assert code == 2
    assert err.count("\n") == 1 and f"servohydraulics {command}: error: cannot write {out}/" in err, err
    assert err.strip().endswith("[Errno 28] No space left on device")
    assert _files(out) == {}
