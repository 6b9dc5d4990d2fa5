"""``workers.blas_threads``: the loaded OpenBLAS libraries held at one thread inside the block (the
oracle: each library's own thread-count getter), their counts restored after, also on an error;
``sh.identify`` and ``sh.diagnose`` run inside it and leave the counts as they found them."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg  # noqa: F401 (loads scipy's OpenBLAS too)

import servohydraulics as sh
from servohydraulics import workers


def _counts() -> list[int]:
    return [int(get()) for get, _ in workers._openblas()]


def test_blas_threads_holds_and_restores_every_openblas():
    before = _counts()
    if not before:
        pytest.skip("no OpenBLAS library loaded in this process (another BLAS): nothing to hold")
    with workers.blas_threads(1):
        assert _counts() == [1] * len(before)
        a = np.random.default_rng(0).standard_normal((300, 300))
        assert np.allclose(a @ np.linalg.inv(a), np.eye(300), atol=1e-8)  # BLAS still computes
    assert _counts() == before
    with pytest.raises(RuntimeError), workers.blas_threads(1):
        raise RuntimeError("inside")
    assert _counts() == before


def test_identify_and_diagnose_leave_the_counts(monkeypatch):
    before = _counts()
    seen = []
    real = workers.blas_threads

    def spy(n=1):
        seen.append(n)
        return real(n)

    monkeypatch.setattr(workers, "blas_threads", spy)
    t = np.arange(4001) * 1e-3
    u = 2e-3 * np.sin(2 * np.pi * 2.0 * t) * np.minimum(t / 0.5, 1.0)
    rig = sh.zhao2003()
    sim = sh.simulate(rig, "displacement", command=u, dt=1e-3)
    rec = sh.Response({"time": t, "command": u, "displacement": sim.displacement, "force": sim.force})
    sh.identify([rec], rig=rig, fit=["G_p"], channels=["displacement"], frequency_stage=False, progress=False)
    sh.diagnose(rec, rig, mode="displacement", progress=False, max_effects=1, candidates=["viscous_damping"])
    assert seen == [1, 1] and _counts() == before
