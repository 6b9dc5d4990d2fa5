"""RPsD on the numerical-substructure and tracking-compensator concepts (issue 22): the paper's
defaults reproduce run_rpsd as it was before (tests/data/rpsd_reference.npz, written by
scripts/rpsd_reference.py on the base commit)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import servohydraulics as sh

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("rpsd_reference", ROOT / "scripts" / "rpsd_reference.py")
reference = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(reference)
DATA = np.load(ROOT / "tests" / "data" / "rpsd_reference.npz")


@pytest.mark.parametrize("key,kw", list(reference.cases()), ids=[k for k, _ in reference.cases()])
def test_default_rpsd_is_bit_identical_to_the_base_commit(key, kw):
    r = sh.run_rpsd(sh.zhao2003(), **kw)
    for ch in reference.CHANNELS:
        np.testing.assert_array_equal(r.channels[ch], DATA[f"{key}/{ch}"], err_msg=f"{key}/{ch}")
