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


# ----------------------------------------------------------------------------- 10: user mistakes, named

def _record(path: Path, n: int = 1000, change=None) -> Path:
    """The lab record cut to ``n`` samples, with ``change(columns)`` applied."""
    res = sh.simulate(sh.zhao2003(), mode="displacement", command=noise_command(), dt=DT)
    cols = {k: np.asarray(res.channels[k], dtype=float)[:n].copy() for k in ("time", "command", "displacement",
                                                                             "force")}
    if change is not None:
        change(cols)
    sh.write_record(path, cols)
    return path


def _set(name, value, row=None):
    def change(cols):
        if row is None:
            cols[name][:] = value
        else:
            cols[name][row] = value

    return change


MISTAKES = [  # (command, samples, change, flags, the message's text)
    ("identify", 1000, None, ["--dt", "0"], "error: invalid dt = 0.0: must be finite and > 0"),
    ("identify", 1000, None, ["--dt", "nan"], "error: invalid dt = nan: must be finite and > 0"),
    ("identify", 1000, None, ["--dt", "1e-9"], "error: invalid dt = 1e-09: 1,998,000,001 controller samples for "
                                                "the record's 1,000 at 0.002 s, more than the 50,000,000 allowed"),
    ("identify", 1000, None, ["--dt", "3e-4"], "error: invalid dt = 0.0003: the controller sample must divide"),
    ("identify", 1000, None, ["--dt", "1e300"], "error: invalid dt = 1e+300: longer than the record"),
    ("compare", 1000, None, ["--dt", "1e300"], "error: invalid dt = 1e+300: longer than the record"),
    ("identify", 1000, None, ["--max-nfev", "0"], "error: invalid max_nfev = 0: must be an integer >= 1"),
    ("identify", 11, None, [], "rec.csv: invalid record length = 11 samples: compare and identify need at least 384"),
    ("identify", 11, None, ["--rig", None], "invalid record length = 11 samples"),
    ("compare", 300, None, [], "rec.csv: invalid record length = 300 samples"),
    ("compare", 1000, _set("command", 1.0), [], "rec.csv: invalid command = constant 1.0: no energy"),
    ("identify", 1000, _set("command", 1.0), [], "rec.csv: invalid command = constant 1.0: no energy"),
    ("compare", 1000, _set("force", 1e300, 7), [], "rec.csv: invalid force[7] = 1e+300: must be finite and within"),
    ("identify", 1000, _set("force", -1e300, 7), [], "rec.csv: invalid force[7] = -1e+300"),
    ("identify", 1000, _set("displacement", 0.0), ["--specimen", "mr_damper", "--mode", "force"],
     "rec.csv: invalid displacement = constant 0.0: the generic start scales the rig from the motion"),
    ("identify", 400, _set("force", 0.0), ["--rig", None, "--mode", "force", "--fit", "K_v"],
     "rec.csv: invalid frequency response = none usable"),
]


@pytest.mark.parametrize("command, samples, change, flags, text", MISTAKES,
                         ids=[f"{m[0]}-{i}" for i, m in enumerate(MISTAKES)])
def test_identify_and_compare_mistakes_are_named(lab, tmp_path, capsys, command, samples, change, flags, text):
    """Each once ended in an opaque message ('padlen, which is 15', 'no frequency with coherence'
    after a --dt 0 the fit never used, '`max_nfev` must be None or positive integer', 'invalid
    command: constant' naming no record) or an internal error (RuntimeWarning: overflow)."""
    rec = _record(tmp_path / "rec.csv", samples, change)
    rig = lab[1]
    flags = [str(rig) if f is None else f for f in flags]
    argv = [command, rec, "--out", tmp_path / "out"]
    argv += [] if "--mode" in flags else ["--mode", "displacement"]
    argv += [] if command == "identify" or "--rig" in flags else ["--rig", rig]
    argv += ["--quiet", "--fit=K_v", "--max-nfev=2"] if command == "identify" and "--max-nfev" not in flags else []
    code, _, err = _cli(capsys, *argv, *flags)
    assert code == 2, err
    assert err.count("\n") == 1 and text in err, err
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())


# ----------------------------------------------------------------------------- 11: warnings, run_record

def test_compare_surfaces_the_runs_warnings(lab, tmp_path, capsys):
    """A rig whose stroke is shorter than the record's motion: the run hits the end stop; compare
    used to print only the NRMSE and write no warning.  (The stroke at 0.7 of the motion: the
    record goes beyond it by less than the factor 2 that makes it an error, issue 25: a warning
    of the record's own, and the run's.)"""
    rec, _ = lab
    rig = sh.zhao2003()
    peak = float(np.max(np.abs(sh.read_record(rec).displacement)))
    rig.stroke = 0.7 * peak
    sh.save_rig(rig, tmp_path / "short_stroke.toml")
    code, _, err = _cli(capsys, "compare", rec, "--rig", tmp_path / "short_stroke.toml", "--mode", "displacement",
                        "--out", tmp_path / "out")
    assert code == 0, err
    assert "warning: " in err and "[run_stroke] simulated run: displacement beyond the actuator stroke" in err
    assert "[displacement_beyond_stroke]" in err
    import json

    data = json.loads((tmp_path / "out" / "comparison.json").read_text())
    assert any("beyond the actuator stroke" in w for w in data["warnings"])
    same = sh.identification.compare(sh.read_record(rec), sh.zhao2003(), "displacement")
    assert same.warnings == [] and same.to_dict()["warnings"] == []


@pytest.mark.parametrize("dt", [None, DT / 4, DT * 4])
def test_resampled_runs_keep_every_flag(lab, dt):
    """The flags of a run on a faster or slower controller grid reach the record's rows (the
    slower grid's rows used to carry no flags at all): the stroke warning is the same."""
    from servohydraulics.identification.run import simulate_record

    record = sh.read_record(lab[0])
    rig = sh.zhao2003()
    rig.stroke = 0.5 * float(np.max(np.abs(record.displacement)))
    sim = simulate_record(rig, record, "displacement", dt=dt)
    assert sim.flags.size == record.time.size
    assert any("beyond the actuator stroke" in w for w in sim.warnings())


def test_chunked_run_record_overlaps_by_one_command_as_documented():
    """run_record returns one row per command, row k the state before command[k]; the last command
    is not applied.  Chunks overlapping by one command (the docstring's recipe) equal one run; chunks
    that do not overlap repeat a row and skip a command at every boundary."""
    from servohydraulics import _core
    from servohydraulics.simulate import make_plant

    u = noise_command(600)
    whole, s = _core.run_record(make_plant(sh.zhao2003(), "displacement", DT), u)
    assert s.rows == u.size
    plant = make_plant(sh.zhao2003(), "displacement", DT)
    rows = []
    for k, start in enumerate(range(0, u.size, 200)):
        ch, _ = _core.run_record(plant, u[start:start + 201])
        part = np.asarray(ch["displacement"])[: min(201, u.size - start)]
        rows.append(part if k == 0 else part[1:])
    chunked = np.concatenate(rows)[: u.size]
    assert np.array_equal(chunked, np.asarray(whole["displacement"]))
    plant = make_plant(sh.zhao2003(), "displacement", DT)
    a, _ = _core.run_record(plant, u[:300])
    b, _ = _core.run_record(plant, u[300:])
    assert a["displacement"][-1] == b["displacement"][0]  # the repeated row of naive chunks
    assert not np.array_equal(np.r_[a["displacement"], b["displacement"]], whole["displacement"])


# ----------------------------------------------------------------------------- 5: the evaluation scripts' pools

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("script, args", [("evaluate.py", ["--data", "DIR"]), ("generate.py", ["--out", "DIR/set"])])
@pytest.mark.parametrize("jobs", ["100000", "0"])
def test_evaluation_pools_are_bounded(tmp_path, script, args, jobs):
    """The diagnosis evaluation made ProcessPoolExecutor(max_workers=--jobs) itself: --jobs 100000
    forked until the machine stopped. Now workers.process_pool: a named error before any work."""
    import os
    import subprocess
    import sys

    argv = [sys.executable, str(ROOT / "evaluation" / "diagnose_eval" / script), "--jobs", jobs]
    argv += [a.replace("DIR", str(tmp_path)) for a in args]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    p = subprocess.run(argv, capture_output=True, text=True, timeout=120, env=env)
    assert p.returncode == 2, p.stderr
    assert f"error: invalid --jobs = {jobs}: must be an integer from 1 to" in p.stderr
    assert "Traceback" not in p.stderr
    assert list(tmp_path.iterdir()) == []
