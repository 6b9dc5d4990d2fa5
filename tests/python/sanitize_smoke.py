"""A short smoke run of the Python surface for ``scripts/run.sh sanitize``: the
sanitized ``_core`` (ASan + UBSan) through every binding that moves arrays or
releases the GIL, the error paths (bad tables, bad options, concurrent use)
and threads.  Not collected by pytest (no ``test_`` prefix); any sanitizer
report aborts the interpreter, so reaching the last line is the pass."""

from __future__ import annotations

import threading

import numpy as np

import servohydraulics as sh
from servohydraulics import _core


def expect(exc: type[BaseException], f, *args) -> None:
    try:
        f(*args)
    except exc:
        return
    raise AssertionError(f"{f} did not raise {exc.__name__}")


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
    print(f"sanitize smoke: ok ({len(errors)} concurrent-use error(s) raised on the shared plant)")


if __name__ == "__main__":
    main()
