"""Shared by the property tests (test_fuzz_*.py): the outcome tally and the
count mode.

``SH_FUZZ_STATS=1 pytest -s ...`` prints how the drawn inputs ended.
``SH_FUZZ_COUNT=1`` runs every drawn input and counts the contract violations
instead of failing at the first (hypothesis then does not shrink): that is how
docs/robustness.md counts them before and after (``pytest -s`` to see them).
"""

from __future__ import annotations

import collections
import functools
import os

COUNT = bool(os.environ.get("SH_FUZZ_COUNT"))


class Tally(collections.Counter):
    """How the inputs ended (keys), and ``inputs``: how many the property tests ran."""

    inputs = 0

    def report(self, name: str) -> None:
        if os.environ.get("SH_FUZZ_STATS") or COUNT:
            bad = sum(v for k, v in self.items() if k.startswith("violation"))
            print(f"\n{name}: {self.inputs} inputs, {bad} violations: {dict(sorted(self.items()))}")


def counted(tally: Tally):
    """In count mode, a failing input is tallied as a violation (by exception type
    and the first words of its message) instead of failing the test."""

    def wrap(test):
        @functools.wraps(test)
        def run(*args, **kwargs):
            tally.inputs += 1
            if not COUNT:
                return test(*args, **kwargs)
            try:
                return test(*args, **kwargs)
            except Exception as e:  # noqa: BLE001 - counting every kind of violation
                words = " ".join(str(e).split()[:4])
                tally[f"violation: {type(e).__name__}: {words}"] += 1

        return run

    return wrap
