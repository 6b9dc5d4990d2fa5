"""A short smoke run of the Python surface for ``scripts/run.sh sanitize``: the
sanitized ``_core`` (ASan + UBSan) through every binding that moves arrays or
releases the GIL, the error paths (bad tables, bad options, concurrent use)
and threads; the RTHS loop calling a Python controller (and one that raises),
``identify`` on a short record, and the FMU export with the exported (sanitized)
FMU binary run through fmpy: a plant and an EFT controller in closed loop, equal
to the library's run, and a hostile host.  Not collected by pytest (no ``test_`` prefix); any sanitizer
report aborts the interpreter, so reaching the last line is the pass."""

from __future__ import annotations

import tempfile
import threading
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics import _core


def expect(exc: type[BaseException], f, *args) -> None:
    try:
        f(*args)
    except exc:
        return
    raise AssertionError(f"{f} did not raise {exc.__name__}")


class Proportional:
    """A Python controller in the C++ RTHS loop: a gain on the tracking error; raises at sample ``fail_at``."""

    def __init__(self, fail_at: int = -1):
        self.k, self.fail_at = 0, fail_at

    def reset(self):
        self.k = 0

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
        self.k += 1
        if self.k == self.fail_at:
            raise ValueError("deliberate")
        return desired + 0.5 * (desired - measured)


def rths_with_python_controller() -> None:
    from servohydraulics import rths

    case, rec = rths.embedded_case(1), rths.synthetic_record(duration=1.0)
    t = rths.run_trial(case, rec, Proportional(), keep_signals=True)
    assert t.ok and np.all(np.isfinite(t.J))
    expect(RuntimeError, rths.run_trial, case, rec, Proportional(fail_at=50))  # raised through the C++ loop


def identify_short_record() -> None:
    truth = sh.zhao2003()
    dt = 1e-3
    t = np.arange(1000) * dt
    u = 2e-3 * np.sin(2 * np.pi * (0.5 + 2.0 * t) * t)
    sim = sh.simulate(truth, "displacement", u, dt=dt)
    rec = sh.Response({"time": t, "command": u, "displacement": sim.displacement, "force": sim.force})
    start = sh.zhao2003()
    start.G_p *= 1.3
    ident = sh.identify([rec], rig=start, fit=["G_p"], mode="displacement", max_nfev=4,
                         frequency_stage=False, progress=False)
    assert np.isfinite(ident.values["G_p"])


def fmu_through_fmpy() -> None:
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from servohydraulics.fmu import cosimulate

    rig = sh.zhao2003()
    with tempfile.TemporaryDirectory(prefix="sh_sanitize_") as d:
        plant = sh.export_fmu(rig, Path(d) / "plant.fmu", kind="plant", mode="force")
        eft = sh.export_fmu(rig, Path(d) / "eft.fmu", kind="eft")
        ag = 3.0 * np.sin(2 * np.pi * 1.5 * np.arange(300) * 5e-4)
        res, ref = cosimulate(plant, eft, ag), sh.run_eft(rig, ag)
        assert np.array_equal(res.channels["displacement"], ref.displacement)
        expect(ValueError, sh.export_fmu, rig, Path(d) / "bad.fmu", "plant", "force", float("nan"))
        # a hostile host through fmpy: a NaN command, a bad step, steps after an error, reset
        unzipped = extract(str(plant), unzipdir=str(Path(d) / "x"))
        md = read_model_description(unzipped)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        s = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="hostile")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        for call in (lambda: s.setReal([vr["command"]], [float("nan")]), lambda: s.doStep(0.0, -1.0),
                     lambda: s.doStep(1.0, 5e-4), lambda: s.getReal([10**6])):
            expect(Exception, call)
        s.setReal([vr["command"]], [1e12])
        try:
            for k in range(100):
                s.doStep(k * 5e-4, 5e-4)
        except Exception:
            expect(Exception, s.doStep, 0.0, 5e-4)
        s.reset()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        s.doStep(0.0, 5e-4)
        s.terminate()
        s.freeInstance()


def main() -> None:
    rig = sh.zhao2003()
    u = 1e-3 * np.sin(np.linspace(0.0, 6.0, 400))
    for method in ("dopri5", "cvode", "rk4"):
        for mode in ("displacement", "force", "free"):
            cmd = u * (1e5 if mode == "force" else 1.0)
            r = sh.simulate(rig, mode, cmd, options=sh.solver_options(method))
            assert r.success and np.all(np.isfinite(r.displacement))
    ag = 0.5 * np.sin(np.linspace(0.0, 20.0, 400))
    assert sh.run_eft(rig, ag, compensation="nonlinear").success
    assert sh.run_rpsd(rig, ag).success
    lead = _core.PhaseLead(0.005, 0.1, 5e-4)
    assert np.all(np.isfinite(lead.filter(ag)))
    # FlowCurve tables that cannot be indexed: a ValueError, never a read out of bounds.
    fc = _core.FlowCurve()
    fc.kind = _core.FlowCurve.Kind.Table
    for opening, flow in (([], []), ([0.0], [0.0]), ([0.0, 0.5, 1.0], [0.0, 0.5])):
        fc.opening, fc.flow = opening, flow
        for f in (fc.eval, fc.slope, fc.inverse):
            expect(ValueError, f, 0.3)
    bad = sh.zhao2003()
    bad.flow_curve = fc
    expect(ValueError, sh.simulate, bad, "displacement", u)
    expect(ValueError, lambda: sh.solver_options("rk4", rk4_substeps=-1))
    expect(ValueError, sh.simulate, rig, "displacement", np.array([0.0, np.nan]))
    # One plant per thread runs; one plant from two threads raises.
    results: list = [None] * 4

    def one(i: int) -> None:
        results[i] = sh.simulate(rig, "displacement", u).displacement

    threads = [threading.Thread(target=one, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(results[0], r) for r in results)
    plant = sh.make_plant(rig, "displacement")
    long_u = np.full(40_000, 1e-3)
    errors: list = []

    def shared() -> None:
        try:
            _core.run_record(plant, long_u)
        except sh.ConcurrentUseError as e:
            errors.append(e)

    threads = [threading.Thread(target=shared) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    rths_with_python_controller()
    identify_short_record()
    fmu_through_fmpy()
    print(f"sanitize smoke: ok ({len(errors)} concurrent-use error(s) raised on the shared plant)")


if __name__ == "__main__":
    main()
