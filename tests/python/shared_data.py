"""Access to the data in ``../shared`` (never committed into the project).

``shared_path("rths-data/BENCHMARK.md")`` returns the path, or skips the test
with a clear message when the folder is absent (a user's fresh clone).  With
``SH_REQUIRE_SHARED_DATA=1`` (set by ``.ci/run``) a missing folder fails the
test instead of skipping it.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

#: ``../shared`` next to the project (the repository root's parent), or $SH_SHARED_DIR.
SHARED = Path(os.environ.get("SH_SHARED_DIR", Path(__file__).resolve().parents[2].parent / "shared"))


def shared_path(relative: str) -> Path:
    path = SHARED / relative
    if path.exists():
        return path
    msg = (f"shared data {path} is absent: it is not part of the project (see the README's data section); "
           f"set SH_SHARED_DIR to the folder that holds it")
    if os.environ.get("SH_REQUIRE_SHARED_DATA") == "1":
        pytest.fail(msg + " (SH_REQUIRE_SHARED_DATA=1: required here)", pytrace=False)
    pytest.skip(msg)
