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
from servohydraulics import atomic
from servohydraulics.cli import main

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}


def _cli(capsys, *argv) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


# ----------------------------------------------------------------------------- 5: worker counts

CPUS = os.cpu_count() or 1


@pytest.mark.parametrize("value", [0, -1, 100000, CPUS + 1, 1.5, True, "2"])
def test_worker_counts_are_bounded_by_the_machine(value):
    from servohydraulics import workers

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
    assert f"error: invalid --workers = {argv[-1]}: must be an integer from 1 to {CPUS}" in err


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


def test_a_symlink_loop_is_a_named_error(tmp_path):
    (tmp_path / "a").symlink_to(tmp_path / "b")
    (tmp_path / "b").symlink_to(tmp_path / "a")
    with pytest.raises(atomic.WriteError, match=f"cannot write {tmp_path / 'a'}: .*Too many levels of symbolic"):
        atomic.write_text(tmp_path / "a", "x")
    assert (tmp_path / "a").is_symlink() and sorted(os.listdir(tmp_path)) == ["a", "b"]


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


# ----------------------------------------------------------------------------- 8: the FMU exporter

@pytest.mark.parametrize("flags, named", [
    (["--dt", "0"], "invalid dt = 0.0"), (["--dt", "nan"], "invalid dt = nan"), (["--dt", "inf"], "invalid dt = inf"),
    (["--dt", "-1"], "invalid dt = -1.0"), (["--dt", "1e-300"], "invalid dt = 1e-300"),
    (["--kind", "rpsd", "--dt", "5e-16"], "invalid dt = 5e-16"), (["--kind", "eft", "--dt", "nan"], "invalid dt = nan"),
    (["--x0", "1e300"], "invalid x0 = 1e+300"), (["--x0=-inf"], "invalid x0 = -inf"),
    (["--name", "a" * 5000], "invalid name = 'aaaa"), (["--name", "a<b&c"], "invalid name = 'a<b&c'"),
    (["--name", "\x01"], "invalid name = '\\x01'"),
    (["--set", "foo=1"], "invalid --set 'foo=1': the plant takes no settings"),
    (["--set", "x"], "invalid --set 'x': expected NAME=VALUE"),
    (["--kind", "eft", "--set", "foo=1"], "invalid --set 'foo=1': the eft takes one of"),
    (["--kind", "eft", "--set", "solver_options=2"], "invalid --set 'solver_options=2'"),
    (["--kind", "eft", "--set", "lead_T=abc"], "invalid lead_T = 'abc'"),
])
def test_fmu_export_validates_like_simulate(tmp_path, capsys, flags, named):
    code, err = _cli(capsys, "fmu", "--out", tmp_path / "f.fmu", *flags)
    assert code == 2, err
    assert "error: " + named in err
    assert "internal error" not in err
    assert os.listdir(tmp_path) == []


def test_export_fmu_api_names_the_bad_argument(tmp_path):
    rig = sh.zhao2003()
    with pytest.raises(ValueError, match="invalid setting 'foo' for kind = 'eft'"):
        sh.export_fmu(rig, tmp_path / "a.fmu", kind="eft", foo=1)
    with pytest.raises(ValueError, match="invalid dt = 1e-09: the FMU's controller sample time"):
        sh.export_fmu(rig, tmp_path / "a.fmu", dt=1e-9)
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_exported_fmu_follows_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        path = sh.export_fmu(sh.zhao2003(), tmp_path / "p.fmu")
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.stat(path).st_mode) == 0o666 & ~mask


class _Fmu:
    """A plant FMU through fmpy with its log kept; start time and dt chosen by the test."""

    def __init__(self, path, workdir, start: float = 0.0, logs: list[str] | None = None, **reals):
        pytest.importorskip("fmpy")
        from fmpy import extract, read_model_description
        from fmu_support import instantiate

        self.logs: list[str] = [] if logs is None else logs
        d = extract(str(path), unzipdir=str(workdir))
        md = read_model_description(d)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu, self._cb = instantiate(d, md, "p", self.logs)
        self.fmu.setupExperiment(startTime=start)
        self.fmu.enterInitializationMode()
        for k, v in reals.items():
            self.fmu.setReal([self.vr[k]], [v])
        self.fmu.exitInitializationMode()
        self.t = start

    def run(self, u, dt: float) -> dict[str, list[float]]:
        names = ["displacement", "velocity", "force", "pressure", "spool"]
        rows = {n: [] for n in names}
        for v in u:
            self.fmu.setReal([self.vr["command"]], [float(v)])
            self.fmu.doStep(currentCommunicationPoint=self.t, communicationStepSize=dt)
            self.t += dt
            for n, y in zip(names, self.fmu.getReal([self.vr[n] for n in names])):
                rows[n].append(y)
        return rows

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def test_fmu_do_step_is_bounded_in_samples(tmp_path):
    """A doStep of 1e8 samples (10 s at the smallest dt) is a named error at once, not hours of work;
    dt = 5e-16 set by the host is refused at initialisation."""
    from fmpy.fmi1 import FMICallException

    path = sh.export_fmu(sh.zhao2003(), tmp_path / "p.fmu", dt=1e-7)
    s = _Fmu(path, tmp_path / "a")
    t0 = time.monotonic()
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=10.0)
    assert time.monotonic() - t0 < 1.0
    assert any("invalid communicationStepSize = 10 s" in m and "more than the 10000000" in m for m in s.logs), s.logs
    s.run([0.001] * 3, 1e-7)  # a bad step size can be retried with a good one
    s.close()
    for i, bad in enumerate((5e-16, float("nan"))):
        logs: list[str] = []
        with pytest.raises(FMICallException):
            _Fmu(path, tmp_path / f"b{i}", logs=logs, dt=bad)
        assert any(f"invalid dt = {bad}" in m for m in logs), logs


# ----------------------------------------------------------------------------- 3: start times

@pytest.mark.parametrize("method", ["dopri5", "cvode", "rk4"])
def test_a_large_start_time_gives_the_response_of_t0_zero(method):
    import numpy as np

    from servohydraulics.simulate import make_plant

    u = 0.002 * np.sin(2 * np.pi * 5 * np.arange(1000) * 5e-4)
    ref = None
    for t0 in (0.0, 1.7e9, 1e10):
        p = make_plant(sh.zhao2003(), "displacement", 5e-4, sh.solver_options(method))
        p.reset(0.0, t0)
        rows = [p.step(v)[1] for v in u]
        y = np.array([[o.displacement, o.force, o.velocity] for o in rows])
        assert rows[-1].time == t0 + 1000 * 5e-4 and p.time == rows[-1].time
        if ref is None:
            ref = y
        assert np.array_equal(y, ref), f"t0 = {t0}: {np.max(np.abs(y - ref))}"


def test_a_non_finite_start_time_is_a_named_error():
    p = sh.Plant(sh.zhao2003(), sh.ControlMode.Displacement, 5e-4)
    for t0 in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(ValueError, match=f"invalid t0 = {t0}: the start time must be finite"):
            p.reset(0.0, t0)
        with pytest.raises(ValueError, match="invalid t0"):
            p.reset_state(p.state, t0)


@pytest.mark.parametrize("t0", [1.7e9, 1e10])
def test_plant_fmu_at_a_unix_start_time_equals_t0_zero(tmp_path, t0):
    import numpy as np

    path = sh.export_fmu(sh.zhao2003(), tmp_path / "p.fmu")
    u = 0.002 * np.sin(2 * np.pi * 5 * np.arange(400) * 5e-4)
    rows = {}
    for start in (0.0, t0):
        s = _Fmu(path, tmp_path / str(start), start=start)
        rows[start] = s.run(u, 5e-4)
        s.close()
    for n in rows[0.0]:
        assert rows[t0][n] == rows[0.0][n], n


def test_fmu_with_a_nan_start_time_is_refused(tmp_path):
    from fmpy.fmi1 import FMICallException

    path = sh.export_fmu(sh.zhao2003(), tmp_path / "p.fmu")
    logs: list[str] = []
    with pytest.raises(FMICallException):
        _Fmu(path, tmp_path / "a", start=float("nan"), logs=logs)
    assert any("invalid startTime = nan: must be finite" in m for m in logs), logs


# ----------------------------------------------------------------------------- 6: benchmark data

def _case_folder(tmp_path: Path, **mats) -> Path:
    import numpy as np
    import scipy.io as sio

    from servohydraulics.rths.data import embedded_case

    c = embedded_case(1)
    d = {"M": c.M, "C": c.C, "K": c.K}
    d.update(mats)
    folder = tmp_path / "data"
    folder.mkdir(exist_ok=True)
    sio.savemat(folder / "Case_1.mat", {k: v for k, v in d.items() if v is not None})
    t = np.arange(200) * 0.01
    sio.savemat(folder / "ElCentroAccelNoScaling.mat", {"ElCentroAccel": np.vstack([t, np.sin(t)])})
    return folder


def _bad_cases():
    import numpy as np

    from servohydraulics.rths.data import embedded_case

    c = embedded_case(1)
    asym = c.K.copy()
    asym[0, 1] *= 1.5
    nan = c.K.copy()
    nan[1, 1] = np.nan
    return [
        ("negative_mass", {"M": -c.M}, "M must be positive definite"),
        ("zero_stiffness", {"K": 0 * c.K}, "K must be positive definite"),
        ("asymmetric_stiffness", {"K": asym}, "K must be symmetric; K[0,1]"),
        ("complex_mass", {"M": c.M * (1 + 1j)}, "M: complex values"),
        ("nan_stiffness", {"K": nan}, "K: entry [1, 1] = nan"),
        ("non_square", {"C": c.C[:2]}, "C must be square"),
        ("sizes_differ", {"M": np.eye(2) * 1000.0}, "M, C and K must have one size"),
        ("text", {"K": "stiff"}, "K: not a numeric array"),
        ("missing_K", {"K": None}, "variable 'K' missing"),
    ]


@pytest.mark.parametrize("name, mats, named", _bad_cases(), ids=[c[0] for c in _bad_cases()])
def test_a_bad_case_file_is_a_named_error(tmp_path, capsys, name, mats, named):
    folder = _case_folder(tmp_path, **mats)
    code, err = _cli(capsys, "rths-benchmark", "--data", folder, "--cases", "1", "--quiet", "--out", tmp_path / "o")
    assert code == 2, err
    assert f"error: {folder / 'Case_1.mat'}" in err and named in err
    assert not (tmp_path / "o").exists()


def _record_folder(tmp_path: Path, rec) -> Path:
    import numpy as np
    import scipy.io as sio

    folder = _case_folder(tmp_path)
    sio.savemat(folder / "ElCentroAccelNoScaling.mat", {"ElCentroAccel": np.asarray(rec)})
    return folder


def _bad_records():
    import numpy as np

    t = np.arange(200) * 0.01
    a = np.sin(t)
    shuffled = t.copy()
    shuffled[[10, 20]] = shuffled[[20, 10]]
    uneven = t.copy()
    uneven[50:] += 0.003
    return [
        ("shuffled_time", np.vstack([shuffled, a]), "time must be increasing"),
        ("uneven_time", np.vstack([uneven, a]), "time must be uniform"),
        ("nan_acceleration", np.vstack([t, np.where(t > 1, np.nan, a)]), "acceleration: entry [101] = nan"),
        ("three_rows", np.vstack([t, a, a]), "must be 2 rows (time, acceleration)"),
        ("complex", np.vstack([t, a * 1j]), "complex values"),
    ]


@pytest.mark.parametrize("name, rec, named", _bad_records(), ids=[r[0] for r in _bad_records()])
def test_a_bad_record_file_is_a_named_error(tmp_path, capsys, name, rec, named):
    folder = _record_folder(tmp_path, rec)
    code, err = _cli(capsys, "rths-benchmark", "--data", folder, "--cases", "1", "--quiet", "--out", tmp_path / "o")
    assert code == 2, err
    assert f"error: {folder / 'ElCentroAccelNoScaling.mat'}" in err and named in err


@pytest.mark.parametrize("content", [b"", b"MATLAB 5.0 MAT-file" + b"\0" * 200, b"\x89PNG\r\n" * 50, b"x" * 3])
def test_a_malformed_mat_file_names_the_file(tmp_path, capsys, content):
    folder = _case_folder(tmp_path)
    (folder / "Case_1.mat").write_bytes(content)
    code, err = _cli(capsys, "rths-benchmark", "--data", folder, "--cases", "1", "--quiet", "--out", tmp_path / "o")
    assert code == 2, err
    assert f"error: {folder / 'Case_1.mat'}: cannot read this MATLAB file" in err


def test_malformed_csv_and_json_copies_name_the_file_and_line(tmp_path):
    from servohydraulics.rths.data import load_case, load_record

    (tmp_path / "elcentro_accel_unscaled.csv").write_text("time,accel\n0,0\n0.02,abc\n")
    with pytest.raises(ValueError, match=r"elcentro_accel_unscaled.csv: line 3 = '0.02,abc'"):
        load_record(tmp_path, "elcentro")
    (tmp_path / "building_cases.json").write_text('{"cases": {"case_1": {"M": [[1]], "C": [[0]]}}}')
    with pytest.raises(ValueError, match=r"building_cases.json: no cases.case_1 with M, C and K"):
        load_case(tmp_path, 1)
    (tmp_path / "building_cases.json").write_text("{not json")
    with pytest.raises(ValueError, match=r"building_cases.json: cannot read this JSON file"):
        load_case(tmp_path, 1)


@pytest.mark.parametrize("layout", ["mat", "."])
def test_the_official_data_pass_the_checks(layout):
    """The official cases and records (both the .mat files and the JSON/CSV copies) are valid."""
    from shared_data import shared_path

    from servohydraulics.rths.data import RECORDS, load_case, load_record

    folder = shared_path("rths-data") / layout
    for n in (1, 2, 3, 4):
        assert load_case(folder, n).M.shape == (3, 3)
    for name in RECORDS:
        assert load_record(folder, name).time.size > 1000



# ----------------------------------------------------------------------------- 10: user mistakes, named

@pytest.fixture
def record_and_rig(tmp_path, capsys):
    assert _cli(capsys, "simulate", "--duration", "0.5", "--dt", "0.001", "--frequency", "5",
                "--out", tmp_path / "rec.csv")[0] == 0
    sh.save_rig(sh.zhao2003(), tmp_path / "rig.toml")
    return tmp_path / "rec.csv", tmp_path / "rig.toml"


@pytest.mark.parametrize("dt, named", [("0", "invalid dt = 0.0: must be finite and > 0"),
                                       ("nan", "invalid dt = nan"), ("-0.001", "invalid dt = -0.001"),
                                       ("1e-9", "invalid dt = 1e-09: 500,000,001 controller samples"),
                                       ("3e-4", "invalid dt = 0.0003: the controller sample must divide")])
def test_compare_dt_is_checked_before_any_allocation(record_and_rig, tmp_path, capsys, dt, named):
    rec, rig = record_and_rig
    code, err = _cli(capsys, "compare", rec, "--rig", rig, "--mode", "displacement", "--out", tmp_path / "c",
                     "--dt", dt)
    assert code == 2 and "error: " + named in err, err


@pytest.mark.parametrize("text", ["a = " + "[" * 5000 + "]" * 5000, "a = " + "{x=" * 3000 + "1" + "}" * 3000])
@pytest.mark.parametrize("command", [["simulate", "--out", "OUT/s.csv"], ["fmu", "--out", "OUT/f.fmu"],
                                     ["compare", "REC", "--mode", "displacement", "--out", "OUT/c"]])
def test_deeply_nested_toml_is_a_named_error(record_and_rig, tmp_path, capsys, text, command):
    deep = tmp_path / "deep.toml"
    deep.write_text(text)
    argv = [str(record_and_rig[0]) if a == "REC" else a.replace("OUT", str(tmp_path)) for a in command]
    code, err = _cli(capsys, *argv, "--rig", deep)
    assert code == 2, err
    assert f"error: rig file {deep} is not valid TOML here: arrays or tables nested too deeply" in err


@pytest.mark.parametrize("command", [[1e-3, 1e-3 + 1e-6j], [1j] * 5])
def test_a_complex_command_is_refused_not_truncated(command):
    with pytest.raises(ValueError, match=r"invalid command\[\d\] = .*j\)?: complex"):
        sh.simulate(sh.zhao2003(), command=command)


def test_a_complex_command_with_zero_imaginary_parts_is_its_real_part():
    import numpy as np

    u = 1e-3 * np.sin(np.arange(200) * 0.05)
    a = sh.simulate(sh.zhao2003(), command=u + 0j)
    b = sh.simulate(sh.zhao2003(), command=u)
    assert np.array_equal(a.displacement, b.displacement)
