"""How the house reads: largest files, longest functions, and where the paper's equations live.

    python scripts/house.py [--root DIR] [--top N]

Prints a Markdown report. Python function lengths come from the AST (first line of the
`def` to its last line); C++ function lengths from a brace matcher over the source with
comments and strings stripped (a body is a top-level or class-level `{...}` preceded by
a `)`-terminated signature). The equation census counts the code lines (comments and docstrings
excluded) where an equation is written, by patterns that match its defining expression (not calls of it).
"""

from __future__ import annotations

import argparse
import ast
import re
from pathlib import Path

CODE_DIRS = ("cpp", "bindings", "python", "scripts", "examples", "benchmarks", "evaluation", "studies")

# The defining expression of each equation or constant, as it appears where it is *written*
# (a call of the one home does not match).  Each pattern is searched in Python and C++ sources.
CENSUS = {
    "Eq (1) loop gain K_v C_F K_s G_p written out": r"K_v\s*\*\s*[\w.]*C_F[\w.]*\s*\*\s*[\w.]*K_s\s*\*\s*[\w.]*G_p"
    r"|K_s\s*\*\s*[\w.]*G_p\s*\*\s*[\w.]*C_F|C_F\w*\s*\*\s*[\w.]*K_s\s*\*\s*[\w.]*G_p",
    "Eq (5) friction law g(v) tanh(v / v_stick) evaluated": r"tanh\(\s*v\s*/\s*[\w.]*v_stick\s*\)",
    "Eq (5) spring softening f_s(x) evaluated": r"k_2\s*\*\s*\(\s*(np\.|std::)?(abs|fabs)\(\s*x\s*\)\s*-",
    "Eq (8) Jacobsen damping F_c / (pi ...)": r"F_c\s*/\s*\(\s*(math\.|np\.)?pi",
    "Fig 1 phase lead discretised (Tustin)": r"bilinear\(\s*\[\s*T|T\s*\*\s*c\s*\+\s*1\.0\)\s*/\s*den",
    "RK4 automatic substep rule": r"h_rho\s*/|/\s*[\w.]*h_rho|_fastest_rate\(",
    "test-method constant 68 ms": r"68e-3|0\.068\b",
    "test-method constant 11.2 ms": r"11\.2e-3|0\.0112\b",
    "rig key metadata rows (key with unit string)": r"\"actuator\",\s*\"K_a\"|'K_a',\s*'m\^5/N'|\bK_a\b.*m\^5/N",
}


def _files(root: Path, exts: tuple[str, ...]) -> list[Path]:
    out = []
    for d in CODE_DIRS:
        for p in sorted((root / d).rglob("*")):
            if p.suffix in exts and "build" not in p.parts and p.is_file() and p.name != "house.py":
                out.append(p)
    return out


def python_functions(path: Path) -> list[tuple[int, str]]:
    try:
        tree = ast.parse(path.read_text())
    except SyntaxError:
        return []
    out = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            out.append((node.end_lineno - node.lineno + 1, f"{node.name} ({node.lineno})"))
    return out


_STRIP = re.compile(r"//[^\n]*|/\*.*?\*/|\"(?:\\.|[^\"\\])*\"|'(?:\\.|[^'\\])*'", re.S)


def cpp_functions(path: Path) -> list[tuple[int, str]]:
    src = _STRIP.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), path.read_text())
    out, depth, i = [], 0, 0
    sig = re.compile(r"([\w:~<>]+)\s*\([^;{}]*\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(->\s*[\w:<>&*]+)?\s*"
                     r"(:[^{;]*)?$", re.S)
    while i < len(src):
        c = src[i]
        if c == "{":
            m = sig.search(src[max(0, i - 400):i])
            if m and m.group(1) not in ("if", "for", "while", "switch", "catch") and depth <= 2:
                j, d = i, 0
                while j < len(src):
                    d += src[j] == "{"
                    d -= src[j] == "}"
                    if d == 0:
                        break
                    j += 1
                start, end = src.count("\n", 0, i) + 1, src.count("\n", 0, j) + 1
                out.append((end - start + 1, f"{m.group(1)} ({start})"))
                i = j + 1
                continue
            depth += 1
        elif c == "}":
            depth = max(0, depth - 1)
        i += 1
    return out


def code_lines(path: Path) -> list[str]:
    """The file's lines with comments and docstrings blanked (strings kept)."""
    text = path.read_text()
    lines = text.splitlines()
    if path.suffix == ".py":
        try:
            tree = ast.parse(text)
        except SyntaxError:
            return lines
        for node in ast.walk(tree):
            if isinstance(node, ast.Expr) and isinstance(getattr(node, "value", None), ast.Constant) \
                    and isinstance(node.value.value, str):
                for i in range(node.lineno - 1, node.end_lineno):
                    lines[i] = ""
        return [re.sub(r"(^|\s)#.*$", "", ln) for ln in lines]
    text = re.sub(r"/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text, flags=re.S)
    return [re.sub(r"//.*$", "", ln) for ln in text.splitlines()]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=str(Path(__file__).resolve().parents[1]))
    ap.add_argument("--top", type=int, default=10)
    a = ap.parse_args(argv)
    root = Path(a.root)
    files = _files(root, (".py", ".cpp", ".hpp"))
    rel = {p: str(p.relative_to(root)) for p in files}

    print("## Largest files (lines)\n")
    for n, p in sorted(((len(p.read_text().splitlines()), p) for p in files), key=lambda t: -t[0])[: a.top]:
        print(f"- {n:5d}  {rel[p]}")

    funcs = []
    for p in files:
        f = python_functions(p) if p.suffix == ".py" else cpp_functions(p)
        funcs += [(n, f"{rel[p]}: {name}") for n, name in f]
    funcs.sort(key=lambda t: -t[0])
    print("\n## Longest functions (lines)\n")
    for n, name in funcs[: a.top]:
        print(f"- {n:5d}  {name}")
    over = [f for f in funcs if f[0] > 60]
    print(f"\nfunctions over 60 lines: {len(over)} of {len(funcs)}")
    for area in ("reproduce", "paper/", "diagnos"):
        print(f"  in {area!r}: {sum(area in name for _, name in over)}")

    print("\n## Where each equation is written (places)\n")
    for label, pat in CENSUS.items():
        rx = re.compile(pat)
        hits = [f"{rel[p]}:{i}" for p in files for i, line in enumerate(code_lines(p), 1)
                if rx.search(line)]
        print(f"- {label}: {len(hits)}" + (f"  ({', '.join(hits[:8])}{' ...' if len(hits) > 8 else ''})"
                                          if hits else ""))


if __name__ == "__main__":
    main()
