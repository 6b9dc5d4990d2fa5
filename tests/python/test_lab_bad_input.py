"""Bad input to the record readers and checks, through the three commands that read records
(issue 25, "Bad input"): every case ends in one ``error: ...`` line naming the file, the column
or field and the value, exit 2, no traceback, nothing written in the output folder."""

from __future__ import annotations

import numpy as np
import pytest
from cli_cases import run_case

import servohydraulics as sh

N, DT = 600, 1e-3


def _cols():
    t = np.arange(N) * DT
    u = 0.002 * np.sin(2 * np.pi * 3 * t)
    return {"time": t, "command": u, "displacement": 0.95 * u, "force": 2e5 * u}


def _csv(path, cols, header=None, sep=","):
    rows = "\n".join(sep.join(f"{v[k]:.9g}" for v in cols.values()) for k in range(N))
    path.write_text(sep.join(header or cols) + "\n" + rows + "\n")
    return path


def _daq(path, count=N, truncate=False):
    c = _cols()
    lines = ["Header Size:  7", "Version:  2", "Sampling Interval:  0.001", "Sampling Rate:  1000",
             f"Sample Count:  {count}", "Device Serial Number:  0",
             "Sample Number, CHANNEL0, CHANNEL1, CHANNEL2, Events"]
    lines += [f"{k + 1:>8}, {100 * c['displacement'][k]:.4f}, {c['force'][k] / 1e3:.4f}, {100 * c['command'][k]:.4f}"
              for k in range(N)]
    text = "\n".join(lines) + "\n"
    path.write_text(text[:-12] if truncate else text)
    return path


def _layout(path):
    path.write_text('sample_interval = "Sampling Interval"\nsample_count = "Sample Count"\n[columns]\n'
                    'time = "Sample Number"\ncommand = "CHANNEL2"\ndisplacement = "CHANNEL0"\nforce = "CHANNEL1"\n'
                    '[units]\ntime = "samples"\ncommand = "mm"\ndisplacement = "mm"\nforce = "kN"\n'
                    '[scale]\ncommand = 10.0\ndisplacement = 10.0\n')
    return path


def _cases(d):
    from scipy.io import savemat

    good = _csv(d / "good.csv", _cols())
    c = _cols()
    savemat(d / "novar.mat", {k: v for k, v in c.items() if k != "force"})
    mixed = _csv(d / "mixed.csv", c)
    lines = mixed.read_text().splitlines()
    mixed.write_text("\n".join([lines[0]] + [ln.replace(",", ";") for ln in lines[1:]]) + "\n")
    bad_layout = d / "bad_layout.toml"
    bad_layout.write_text("headerlines = 7\n")
    mm = {**c, "command": 1e3 * c["command"], "displacement": 1e3 * c["displacement"]}
    return [
        ("unknown column", _csv(d / "extra.csv", {**c, "temperature": np.full(N, 20.0)}), [],
         ["extra.csv", "unknown column(s) ['temperature']"]),
        ("mapping to a missing header", good, ["--columns", "force=F"], ["good.csv", "force='F' names no column",
                                                                          "the mapping tried"]),
        ("bad unit", good, ["--units", "displacement=mmm"], ["good.csv", "invalid unit of 'displacement' = 'mmm'"]),
        ("unit of another dimension", good, ["--units", "force=mm"], ["invalid unit of 'force' = 'mm'"]),
        ("bad scale", good, ["--scale", "force=x"], ["invalid --scale force = 'x'"]),
        ("malformed units", good, ["--units", "displacement"], ["invalid --units = 'displacement'"]),
        ("unknown channel", good, ["--columns", "forse=force"], ["invalid --columns channel = 'forse'"]),
        (".mat without the variable", d / "novar.mat", [], ["novar.mat", "missing column(s) ['force']",
                                                           "variables: time (600)"]),
        ("truncated raw file", _daq(d / "trunc.txt", truncate=True), ["--layout", str(_layout(d / "lay.toml"))],
         ["trunc.txt", "could not parse row"]),
        ("header lying about the count", _daq(d / "count.txt", count=N + 100), ["--layout", str(d / "lay.toml")],
         ["count.txt", "invalid header 'Sample Count' = '700': the file has 600 data rows"]),
        ("mixed delimiters", mixed, [], ["mixed.csv", "mixed or unknown delimiters"]),
        ("layout with an unknown key", good, ["--layout", str(bad_layout)], ["bad_layout.toml",
                                                                              "unknown key(s) ['headerlines']"]),
        ("acknowledging an error", good, ["--accept", "time_step"], ["invalid accept = 'time_step'"]),
        ("millimetres read as metres", _csv(d / "mm.csv", mm), [], ["mm.csv", "invalid "]),
    ]


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    d = tmp_path_factory.mktemp("bad")
    sh.save_rig(sh.zhao2003(), d / "rig.toml")
    return d, _cases(d)


@pytest.mark.parametrize("command", ["compare", "identify", "diagnose"])
def test_every_bad_input_is_one_named_error(setup, command):
    d, cases = setup
    for name, path, flags, words in cases:
        out = d / f"out_{command}_{name.replace(' ', '_')}"
        argv = [command, str(path), "--mode", "displacement", "--out", str(out)] + flags
        argv += ["--quiet"] if command != "compare" else []
        argv += ["--rig", str(d / "rig.toml")] if command != "identify" else []
        outcome, code, err = run_case(argv)
        assert code == 2, f"{command} / {name}: exit {code}: {err}"
        lines = [ln for ln in err.strip().splitlines() if ln.strip()]
        assert len(lines) == 1 and "error: " in lines[0] and "Traceback" not in err, f"{command} / {name}: {err}"
        for w in words:  # (identify has no rig: the rig-free check names the millimetre command)
            assert w in err, f"{command} / {name}: {w!r} not in {err}"
        assert not out.exists() or not any(out.iterdir()), f"{command} / {name}: wrote {list(out.iterdir())}"
