"""One Plant from two threads (docs/robustness.md): 10 trials of two threads
running ``_core.run_record`` on the same plant (RK4, 200,000 samples each).
Counts the trials that raised ``ConcurrentUseError`` and those whose results no
serial order of the two runs gives (silent corruption).

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python studies/robustness_race.py
"""

from __future__ import annotations

import threading

import numpy as np

import servohydraulics as sh
from servohydraulics import _core


def main(trials: int = 10) -> None:
    rig, opts = sh.zhao2003(), sh.solver_options("rk4")
    u = 5e-3 * np.sin(2 * np.pi * np.arange(200_000) * 5e-4)
    p0 = sh.make_plant(rig, "displacement", options=opts)
    ref1 = _core.run_record(p0, u)[0]["displacement"]  # the first run, then the second from its end state
    ref2 = _core.run_record(p0, u)[0]["displacement"]
    raised = corrupt = 0
    for _ in range(trials):
        plant = sh.make_plant(rig, "displacement", options=opts)
        res: list = [None, None]
        errors: list = []

        def run(i: int, plant=plant, res=res, errors=errors) -> None:
            try:
                res[i] = _core.run_record(plant, u)[0]["displacement"]
            except RuntimeError as e:
                errors.append(e)

        threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        raised += bool(errors)
        done = [r for r in res if r is not None]
        if len(done) == 2:
            ok = any(np.array_equal(done[0], a) and np.array_equal(done[1], b) for a, b in ((ref1, ref2), (ref2, ref1)))
        else:
            ok = len(done) == 1 and np.array_equal(done[0], ref1)
        corrupt += not ok
    print(f"{trials} trials: {raised} raised a ConcurrentUseError, {corrupt} with results no serial order gives")


if __name__ == "__main__":
    main()
