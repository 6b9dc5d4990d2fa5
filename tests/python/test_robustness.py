"""Thread safety and files written whole or not at all (docs/robustness.md).

Contracts: separate objects in separate threads give results bit-identical to
serial runs; one object used from two threads at once raises
ConcurrentUseError (a RuntimeError) instead of corrupting it, and the object
works again afterwards; a writer that fails part-way (a full disk, simulated
here by a savetxt that writes half and raises ENOSPC) leaves no file, no
temporary, the previous content intact, and an OSError naming the file in one
line."""

from __future__ import annotations

import errno
import threading

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.atomic import FileSet, WriteError
from servohydraulics.cli import main

DT = 5e-4


def _commands(n: int = 2000) -> list[np.ndarray]:
    t = np.arange(n) * DT
    return [a * np.sin(2 * np.pi * f * t) for a, f in ((2e-3, 1.0), (5e-3, 3.0), (1e-3, 7.0), (8e-3, 0.5))]


@pytest.mark.parametrize("method", ["dopri5", "cvode", "rk4"])
def test_simulate_from_four_threads_is_bit_identical_to_serial(method):
    rig, opts = sh.zhao2003(), sh.solver_options(method)
    cmds = _commands()
    serial = [sh.simulate(rig, "displacement", u, options=opts) for u in cmds]
    threaded: list = [None] * len(cmds)
    barrier = threading.Barrier(len(cmds))

    def run(i: int) -> None:
        barrier.wait()  # start together so that the runs overlap
        threaded[i] = sh.simulate(rig, "displacement", cmds[i], options=opts)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(len(cmds))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(serial, threaded):
        assert list(a.channels) == list(b.channels)
        for name in a.channels:
            assert np.array_equal(a.channels[name], b.channels[name]), name


def test_loops_from_threads_are_bit_identical_to_serial():
    rig = sh.zhao2003()
    ags = [0.3 * u / np.max(np.abs(u)) for u in _commands(1500)]
    serial = [sh.run_eft(rig, ag, compensation="nonlinear").force for ag in ags[:2]]
    serial += [sh.run_rpsd(rig, ag).displacement for ag in ags[2:]]
    out: list = [None] * 4

    def run(i: int) -> None:
        out[i] = (sh.run_eft(rig, ags[i], compensation="nonlinear").force if i < 2
                  else sh.run_rpsd(rig, ags[i]).displacement)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(a, b) for a, b in zip(serial, out))


def _race(run, poke) -> list[Exception]:
    """Runs run() in a thread while this thread calls poke() until run is done;
    returns the ConcurrentUseErrors poke raised (run's own errors are re-raised)."""
    started, done, failure = threading.Event(), threading.Event(), []

    def worker() -> None:
        started.set()
        try:
            run()
        except Exception as e:  # noqa: BLE001
            failure.append(e)
        finally:
            done.set()

    t = threading.Thread(target=worker)
    t.start()
    started.wait()
    errors = []
    while not done.is_set():
        try:
            poke()
        except sh.ConcurrentUseError as e:
            errors.append(e)
    t.join()
    if failure:
        raise failure[0]
    return errors


def test_one_plant_from_two_threads_raises_a_clear_error():
    plant = sh.make_plant(sh.zhao2003(), "displacement")
    u = np.full(20_000, 1e-3)  # CVODE: long enough (~0.3 s) for the other thread to meet it busy
    errors = _race(lambda: _core.run_record(plant, u), plant.observe)
    assert errors, "the plant was used from two threads without an error"
    text = str(errors[0])
    assert isinstance(errors[0], RuntimeError)
    assert "Plant.observe" in text and "run_record" in text and "another thread" in text
    # The guard is released: the plant works again, and a second concurrent run is refused too.
    plant.reset()
    assert plant.step(1e-3)[0].ok()
    errors = _race(lambda: _core.run_record(plant, u), lambda: _core.run_record(plant, u[:10]))
    assert errors and "run_record" in str(errors[0])


def test_a_loop_and_its_plant_from_two_threads_raise():
    test = _core.EffectiveForceTest(sh.zhao2003(), sh.loops.eft_config())
    ag = 0.3 * np.sin(np.linspace(0, 30, 8_000))
    errors = _race(lambda: test.run(ag), lambda: _core.run_record(test.plant, np.zeros(5)))
    assert errors and "EffectiveForceTest.run" in str(errors[0])
    errors = _race(lambda: test.run(ag), lambda: test.step(0.0))
    assert errors and "EffectiveForceTest.step" in str(errors[0])


def test_phase_lead_filter_from_two_threads_raises():
    lead = _core.PhaseLead(0.005, 0.1, DT)
    u = np.random.default_rng(0).standard_normal(2_000_000)
    errors = _race(lambda: lead.filter(u), lambda: lead.step(0.0))
    assert errors and "PhaseLead.filter" in str(errors[0])


# ---- files ------------------------------------------------------------------------------------------
def _half_then_enospc(real):
    def savetxt(fname, X, *args, **kwargs):
        real(fname, X[: len(X) // 2], *args, **kwargs)  # half the rows reach the disk
        raise OSError(errno.ENOSPC, "No space left on device")

    return savetxt


def test_to_csv_on_a_full_disk_leaves_no_partial_file(tmp_path, monkeypatch):
    res = sh.simulate(sh.zhao2003(), "displacement", _commands(400)[0])
    path = tmp_path / "record.csv"
    res.to_csv(path)
    before = path.read_bytes()
    monkeypatch.setattr(np, "savetxt", _half_then_enospc(np.savetxt))
    with pytest.raises(OSError) as info:
        res.to_csv(path)
    assert str(info.value) == f"cannot write {path}: [Errno 28] No space left on device"
    assert path.read_bytes() == before  # the previous content, whole
    new = tmp_path / "new.csv"
    with pytest.raises(OSError):
        res.to_csv(new)
    assert not new.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["record.csv"]  # no temporaries


def test_cli_simulate_on_a_full_disk_is_one_line_and_no_file(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(np, "savetxt", _half_then_enospc(np.savetxt))
    out = tmp_path / "out.csv"
    code = main(["simulate", "--duration", "0.05", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.strip() == f"servohydraulics simulate: error: cannot write {out}: [Errno 28] No space left on device"
    assert list(tmp_path.iterdir()) == []


def test_a_set_of_files_is_written_together_or_not_at_all(tmp_path):
    (tmp_path / "b.txt").write_text("old")
    with pytest.raises(WriteError, match=r"cannot write .*c\.txt: \[Errno 28\]"):
        with FileSet() as files:
            files.write_text(tmp_path / "a.txt", "new a")
            files.write_text(tmp_path / "b.txt", "new b")
            files.path(tmp_path / "c.txt")
            raise OSError(errno.ENOSPC, "No space left on device")  # the third file fails
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.txt"]
    assert (tmp_path / "b.txt").read_text() == "old"
    with FileSet() as files:
        files.write_text(tmp_path / "a.txt", "new a")
        files.write_text(tmp_path / "b.txt", "new b")
    assert (tmp_path / "a.txt").read_text() == "new a" and (tmp_path / "b.txt").read_text() == "new b"


def test_save_rig_and_figures_are_atomic(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    from servohydraulics.plots import save

    rig_path = sh.save_rig(sh.zhao2003(), tmp_path / "rig.toml")
    assert sh.load_rig(rig_path) == sh.zhao2003()
    fig = Figure()
    fig.subplots().plot([0, 1], [0, 1])
    png = save(fig, tmp_path / "f.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(OSError, match=r"cannot write .*missing.*g\.png"):
        save(fig, tmp_path / "missing" / "g.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png", "rig.toml"]
