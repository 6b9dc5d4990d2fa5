"""Hand-made bad invocations of the command line, shared by test_fuzz_cli.py and
docs/robustness.md's before/after count.

Each case is (name, argv, expected): ``expected`` is a text the one-line error
must contain (the field, column, value or file).  ``run_case`` calls
``cli.main`` in-process and classifies the outcome; ``python cli_cases.py``
prints the counts for whatever ``servohydraulics`` is importable (that is how
the "before" count of the starting commit was taken).
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import tempfile
from pathlib import Path

HEADER = "time,command,displacement,force"


def _rows(n: int = 5, dt: float = 5e-4) -> str:
    return "\n".join(f"{k * dt:.6g},0,0,0" for k in range(n))


RIGS = {
    "huge_int": "[structure]\nm = 1" + "0" * 400 + "\n",
    "huge_int_digits": "[structure]\nm = " + "9" * 5000 + "\n",
    "bad_toml": "[structure\nm = 1\n",
    "unknown_key": "[structure]\nmass = 1.0\n",
    "unknown_section": "[nonsense]\nm = 1.0\n",
    "negative": "[structure]\nm = -7084.0\n",
    "nan": "[structure]\nm = nan\n",
    "inf": "[actuator]\nA = inf\n",
    "string": "[structure]\nm = \"heavy\"\n",
    "bool": "[structure]\nm = true\n",
    "table_1pt": "[servovalve.flow_curve]\nkind = \"table\"\nopening = [0.0]\nflow = [0.0]\n",
    "table_short_flow": "[servovalve.flow_curve]\nkind = \"table\"\nopening = [0.0, 0.5, 1.0]\nflow = [0.0, 0.5]\n",
    "table_0pt": "[servovalve.flow_curve]\nkind = \"table\"\nopening = []\nflow = []\n",
    "bad_kind": "[servovalve.flow_curve]\nkind = \"spline\"\n",
    "effects_number": "[effects]\ncoulomb_friction = 1\n",
}
RIG_EXPECT = {
    "huge_int": "structure.m", "huge_int_digits": "", "bad_toml": "TOML", "unknown_key": "structure.mass",
    "unknown_section": "nonsense", "negative": "m = -7084", "nan": "structure.m", "inf": "actuator.A",
    "string": "structure.m", "bool": "structure.m", "table_1pt": "flow_curve.opening",
    "table_short_flow": "flow_curve.flow", "table_0pt": "flow_curve.opening", "bad_kind": "flow_curve.kind",
    "effects_number": "effects.coulomb_friction",
}
CSVS = {
    "duplicate": "time,command,displacement,force,force\n" + "\n".join(f"{k * 5e-4:.6g},0,0,0,0" for k in range(5)),
    "missing_column": "time,command,displacement\n" + "\n".join(f"{k * 5e-4:.6g},0,0" for k in range(5)),
    "unknown_column": HEADER + ",temperature\n" + "\n".join(f"{k * 5e-4:.6g},0,0,0,20" for k in range(5)),
    "empty": "",
    "header_only": HEADER + "\n",
    "one_row": HEADER + "\n0,0,0,0\n",
    "nonuniform": HEADER + "\n0,0,0,0\n0.0005,0,0,0\n0.0015,0,0,0\n0.002,0,0,0\n",
    "decreasing": HEADER + "\n0,0,0,0\n0.0005,0,0,0\n0.0004,0,0,0\n",
    "nan": HEADER + "\n0,0,0,0\n0.0005,nan,0,0\n0.001,0,0,0\n",
    "text": HEADER + "\n0,0,0,0\n0.0005,abc,0,0\n0.001,0,0,0\n",
    "ragged": HEADER + "\n0,0,0,0\n0.0005,0,0\n0.001,0,0,0\n",
    "semicolon": HEADER.replace(",", ";") + "\n" + _rows().replace(",", ";"),  # read (issue 25), all zero
    "mixed_delimiters": HEADER + "\n" + _rows().replace(",", ";"),
}
CSV_EXPECT = {
    "duplicate": "'force' appears twice", "missing_column": "missing column", "unknown_column": "temperature",
    "empty": "missing column", "header_only": "no data rows", "one_row": "at least 2 rows",
    "nonuniform": "uniform", "decreasing": "increasing", "nan": "'command'", "text": "could not parse",
    "ragged": "could not parse", "semicolon": "'displacement' is all zero", "mixed_delimiters": "mixed or unknown",
}


def make_cases(root: Path) -> list[tuple[str, list[str], str]]:
    """(name, argv, expected text) of every bad invocation; files are made under root."""
    root.mkdir(parents=True, exist_ok=True)
    out = str(root / "out.csv")
    cases: list[tuple[str, list[str], str]] = []
    sim = ["simulate", "--duration", "0.01"]
    for name, flag, value, expect in [
        ("dt_zero", "--dt", "0", "dt = 0"), ("dt_negative", "--dt", "-1", "dt = -1"),
        ("dt_nan", "--dt", "nan", "dt = nan"), ("dt_inf", "--dt", "inf", "dt = inf"),
        ("dt_tiny", "--dt", "1e-300", "samples"), ("duration_zero", "--duration", "0", "duration = 0"),
        ("duration_negative", "--duration", "-5", "duration = -5"), ("duration_huge", "--duration", "1e300", "samples"),
        ("duration_nan", "--duration", "nan", "duration = nan"), ("frequency_zero", "--frequency", "0", "frequency"),
        ("frequency_nan", "--frequency", "nan", "frequency"), ("amplitude_nan", "--amplitude", "nan", "amplitude"),
        ("amplitude_inf", "--amplitude", "inf", "amplitude"), ("x0_nan", "--x0", "nan", "x0"),
        ("x0_huge", "--x0", "1e300", "x0"), ("dt_text", "--dt", "abc", "--dt"),
        ("mode_bogus", "--mode", "bogus", "--mode"),
    ]:
        cases.append((f"simulate {name}", sim + [flag, value, "--out", out], expect))
    a_dir = root / "a_directory"
    a_dir.mkdir(exist_ok=True)
    a_file = root / "a_file.txt"
    a_file.write_text("not a directory\n")
    cases += [
        ("simulate out_is_directory", sim + ["--out", str(a_dir)], str(a_dir)),
        ("simulate out_parent_missing", sim + ["--out", str(root / "missing" / "x.csv")], "x.csv"),
        ("simulate out_under_file", sim + ["--out", str(a_file / "x.csv")], "x.csv"),
        ("simulate out_empty", sim + ["--out", ""], "directory"),
        ("simulate rig_missing", sim + ["--rig", str(root / "missing.toml"), "--out", out], "missing.toml"),
        ("simulate rig_directory", sim + ["--rig", str(a_dir), "--out", out], str(a_dir)),
    ]
    binary = root / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00\x01garbage\x80\x81")
    cases.append(("simulate rig_binary", sim + ["--rig", str(binary), "--out", out], "binary.toml"))
    for name, text in RIGS.items():
        p = root / f"rig_{name}.toml"
        p.write_text(text)
        cases.append((f"simulate rig_{name}", sim + ["--rig", str(p), "--out", out], RIG_EXPECT[name]))
    good_rig = root / "rig_good.toml"
    good_rig.write_text("[structure]\nm = 7084.0\n")
    diag = ["--rig", str(good_rig), "--mode", "displacement", "--out", str(root / "diag"), "--quiet"]
    for name, text in CSVS.items():
        p = root / f"record_{name}.csv"
        p.write_text(text)
        cases.append((f"diagnose csv_{name}", ["diagnose", str(p)] + diag, CSV_EXPECT[name]))
    nonutf8 = root / "record_latin1.csv"
    nonutf8.write_bytes((HEADER + "\n0,0,0,0\n").encode() + b"0.0005,\xe9,0,0\n")
    cases += [
        ("diagnose csv_not_utf8", ["diagnose", str(nonutf8)] + diag, "record_latin1.csv"),
        ("diagnose csv_missing", ["diagnose", str(root / "nope.csv")] + diag, "nope.csv"),
        ("diagnose csv_directory", ["diagnose", str(a_dir)] + diag, str(a_dir)),
        ("diagnose rig_missing", ["diagnose", str(root / "record_one_row.csv"), "--rig", str(root / "none.toml"),
                                  "--mode", "displacement", "--out", str(root / "diag")], "none.toml"),
        ("diagnose mode_missing", ["diagnose", str(root / "record_one_row.csv"), "--rig", str(good_rig),
                                   "--out", str(root / "diag")], "--mode"),
        ("reproduce workers_zero", ["reproduce", "--workers", "0", "--out", str(root / "rep")], "--workers"),
        ("reproduce workers_negative", ["reproduce", "--workers", "-3", "--out", str(root / "rep")], "--workers"),
        ("demo out_is_file", ["demo", "--quick", "--out", str(a_file)], "a_file.txt"),
        ("no_command", [], "command"),
        ("unknown_command", ["frobnicate"], "frobnicate"),
    ]
    return cases


def run_case(argv: list[str]) -> tuple[str, int | None, str]:
    """Runs the CLI in-process: (outcome, exit code, stderr).  outcome is "error"
    (a clean failure: exit code 2 or 1, no traceback), "ok" (exit 0) or
    "traceback" (an exception escaped main)."""
    from servohydraulics.cli import main

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as e:  # argparse: usage and one error line, no traceback
            code = e.code if isinstance(e.code, int) else 2
        except BaseException as e:  # noqa: BLE001 - counting what escapes
            return "traceback", None, f"{type(e).__name__}: {e}"
    return ("ok" if code == 0 else "error"), code, err.getvalue()


def main() -> int:
    with tempfile.TemporaryDirectory() as d:
        cases = make_cases(Path(d))
        counts = {"traceback": 0, "unnamed": 0, "clean": 0, "ok": 0}
        for name, argv, expect in cases:
            outcome, code, text = run_case(argv)
            if outcome == "error" and expect not in text:
                outcome = "unnamed"
            counts["clean" if outcome == "error" else outcome] += 1
            if outcome != "error":
                print(f"{outcome:9s} {name}: {' '.join(text.split())[:160]}")
        print(f"{len(cases)} bad invocations: {counts}")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("MPLBACKEND", "Agg")
    sys.exit(main())
