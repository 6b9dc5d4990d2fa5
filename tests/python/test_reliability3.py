"""Reproducers of issue 26 ("Reliability 3"): worker counts, atomic writers on
special files, the FMU exporter's validation, start times, benchmark data, CLI
mistakes.  Each test is a hostile input that once gave a wrong output, a hang,
a fork bomb or an internal error."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import servohydraulics as sh
from servohydraulics import atomic, workers
from servohydraulics.cli import main

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}


def _cli(capsys, *argv) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


# ----------------------------------------------------------------------------- 5: worker counts

@pytest.mark.parametrize("value", [0, -1, 100000, workers.cpu_count() + 1, 1.5, True, "2"])
def test_worker_counts_are_bounded_by_the_machine(value):
    with pytest.raises(ValueError, match=f"invalid max_workers = {value!r}: must be an integer from 1 to"):
        workers.check_workers(value, "max_workers")
    with pytest.raises(ValueError, match="invalid max_workers"):
        sh.sweep({"structure.k": [1e6]}, max_workers=value, progress=False)


@pytest.mark.parametrize("argv", [["rths-benchmark", "--perturbed", "1", "--workers", "100000"],
                                  ["rths-benchmark", "--workers", "0"],
                                  ["reproduce", "--workers", "100000"], ["reproduce", "--workers", "-3"]])
def test_cli_worker_count_is_a_named_error_before_any_process(tmp_path, capsys, argv):
    code, err = _cli(capsys, *argv, "--out", tmp_path / "o")
    assert code == 2
    assert f"error: invalid --workers = {argv[-1]}: must be an integer from 1 to {workers.cpu_count()}" in err


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split(")")[-1].split()[0] != "Z"  # a zombie is dead, awaiting its reaper
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
def test_pool_workers_die_with_their_parent(tmp_path):
    """SIGKILL the process owning the pool (no shutdown, no atexit): its workers must not outlive it."""
    script = textwrap.dedent("""
        import os, sys, time
        from servohydraulics.workers import process_pool
        pool = process_pool(2)
        futures = [pool.submit(time.sleep, 600) for _ in range(2)]
        time.sleep(1.0)
        print(" ".join(str(p) for p in pool._processes), flush=True)
        time.sleep(600)
    """)
    parent = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=ENV)
    try:
        pids = [int(p) for p in parent.stdout.readline().split()]
        assert len(pids) == 2 and all(_alive(p) for p in pids)
    finally:
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        parent.stdout.close()
    deadline = time.monotonic() + 10
    while any(_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    orphans = [p for p in pids if _alive(p)]
    for p in orphans:  # do not leave them behind when the test fails
        os.kill(p, signal.SIGKILL)
    assert orphans == []


# ----------------------------------------------------------------------------- 7: atomic writers, special files

def test_a_character_device_is_written_through_not_replaced(tmp_path):
    dev = tmp_path / "null"
    try:
        os.mknod(dev, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # a copy of /dev/null
    except PermissionError:
        pytest.skip("mknod of a character device needs root")
    atomic.write_text(dev, "a record")
    assert stat.S_ISCHR(os.stat(dev).st_mode)
    assert os.listdir(tmp_path) == ["null"]  # no temporary left behind


def test_cli_out_onto_a_character_device_keeps_the_device(tmp_path, capsys):
    dev = tmp_path / "null"
    try:
        os.mknod(dev, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("mknod of a character device needs root")
    assert _cli(capsys, "simulate", "--duration", "0.01", "--out", dev)[0] == 0
    assert stat.S_ISCHR(os.stat(dev).st_mode)


def test_a_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(atomic.WriteError, match=f"cannot write {fifo}: it is a FIFO, not a regular file"):
        atomic.write_text(fifo, "x")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert os.listdir(tmp_path) == ["pipe"]


def test_a_symlink_is_followed_and_kept(tmp_path):
    (tmp_path / "runs").mkdir()
    real = tmp_path / "runs" / "record.csv"
    real.write_text("old")
    link = tmp_path / "latest.csv"
    link.symlink_to(Path("runs") / "record.csv")
    atomic.write_text(link, "new")
    assert link.is_symlink() and os.readlink(link) == str(Path("runs") / "record.csv")
    assert real.read_text() == "new"
    dangling = tmp_path / "next.csv"
    dangling.symlink_to(tmp_path / "runs" / "next_record.csv")
    atomic.write_text(dangling, "created")
    assert dangling.is_symlink() and (tmp_path / "runs" / "next_record.csv").read_text() == "created"
    assert sorted(os.listdir(tmp_path / "runs")) == ["next_record.csv", "record.csv"]


def test_a_file_set_with_a_fifo_touches_nothing(tmp_path):
    os.mkfifo(tmp_path / "b.md")
    (tmp_path / "a.json").write_text("old")
    with pytest.raises(atomic.WriteError, match="FIFO"), atomic.FileSet() as files:
        files.write_text(tmp_path / "a.json", "new")
        files.write_text(tmp_path / "b.md", "new")
    assert (tmp_path / "a.json").read_text() == "old"
    assert sorted(os.listdir(tmp_path)) == ["a.json", "b.md"]


# ----------------------------------------------------------------------------- 11: outputs checked first

def test_check_folder_names_a_folder_that_cannot_hold_files(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.raises(atomic.WriteError, match=f"cannot write {tmp_path / 'file' / 'out'}"):
        atomic.check_folder(tmp_path / "file" / "out")
    assert atomic.check_folder(tmp_path / "new" / "out").is_dir()


def _read_only_folder(tmp_path: Path) -> Path:
    """A folder this process cannot create files in: a chmod 555 one, or (root writes anywhere)
    sysfs, which refuses new files to everyone."""
    if os.geteuid() != 0:
        out = tmp_path / "ro"
        out.mkdir(mode=0o555)
        return out
    out = Path("/sys/kernel")
    try:
        atomic.check_folder(out)
    except atomic.WriteError:
        return out
    pytest.skip("no folder refuses root here")


def test_reproduce_to_a_read_only_folder_fails_before_computing(tmp_path, capsys):
    """A read-only --out: an error naming the folder at once (it computed 12 s before failing)."""
    out = _read_only_folder(tmp_path)
    t0 = time.monotonic()
    code, err = _cli(capsys, "reproduce", "--quick", "--workers", "1", "--out", out)
    assert code == 2
    assert f"error: cannot write {out}: [Errno 13] Permission denied" in err
    assert time.monotonic() - t0 < 2
