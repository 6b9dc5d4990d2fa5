"""The maRTHS benchmark's inputs, read from the folder the user gives (``../shared/marths-data``: the
files of ``FermandoisLab/maRTHS-bmk-RoDeAC``, never shipped), each validated on load: a missing or
corrupt file is a ValueError naming the file (and the variable, line or entry) and the value.

Files (BENCHMARK.md section 9):

* ``ID_Control_plant_100Hz_plantFRAME_SS.json``: A, B, C, D of the identified plant (the ``.mat`` holds
  MATLAB class objects that SciPy cannot read; this JSON copy is what is read);
* ``Initial_parameters.mat``: ``theta0_1``, ``theta0_2`` (4 x 1) and ``P0_1``, ``P0_2`` (4 x 4) of RoDeAC;
* ``FE_Model/REF_SAP2000_Model/K_matrix.csv``, ``M_matrix.csv`` (29 x 29, read as MATLAB's ``csvread``:
  empty fields and short rows are zeros) and ``Joint_DOF.xlsx`` (its column 2, ``Ux``: the DOFs the ground
  acceleration drives, read as ``readmatrix`` does, the header row skipped);
* ``ElCentroAccelNoScaling.mat``, ``KobeAccelNoScaling.mat``, ``MorganAccelNoScaling.mat``: 2 x n
  (time [s], acceleration [m/s^2]).
"""

from __future__ import annotations

import json
import math
import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from ..rths.data import Record, _read_mat, _real_array, check_record

__all__ = ["FS", "DT", "EQ_INTENSITY", "RECORDS", "FILES", "MarthsData", "load_data", "load_record",
           "read_csv_matrix", "read_influence_dofs"]

FS = 1024              #: the benchmark's sample rate [Hz] (main_vmaRTHS.m)
DT = 1.0 / FS          #: 2^-10 s, exact in binary
EQ_INTENSITY = 0.4     #: ground-motion scale factor (main_vmaRTHS.m)

#: record name -> (.mat file, variable)
RECORDS = {
    "elcentro": ("ElCentroAccelNoScaling.mat", "ElCentroAccel"),
    "kobe": ("KobeAccelNoScaling.mat", "KobeAccel"),
    "morgan": ("MorganAccelNoScaling.mat", "MorganAccel"),
}

FE = Path("FE_Model") / "REF_SAP2000_Model"
#: what each input is, by role
FILES = {
    "plant": Path("ID_Control_plant_100Hz_plantFRAME_SS.json"),
    "initial": Path("Initial_parameters.mat"),
    "K": FE / "K_matrix.csv",
    "M": FE / "M_matrix.csv",
    "dofs": FE / "Joint_DOF.xlsx",
}

#: The FE model's least size: the benchmark reads and loads DOFs up to 29 (MarthsDofs).
MIN_DOFS = 29
#: Relative asymmetry a structural matrix may have (the SAP2000 export is symmetric to the last bit).
SYMMETRY_RTOL = 1e-9


@dataclass
class MarthsData:
    """The benchmark's model data (SI: N, m, kg, rad), each array validated."""
    folder: Path
    A: np.ndarray          #: plant state matrix [1/s]
    B: np.ndarray          #: [.. per mm]
    C: np.ndarray
    D: np.ndarray
    theta0: list[np.ndarray]   #: RoDeAC's initial FIR parameters per actuator [-]
    P0: list[np.ndarray]       #: RoDeAC's initial inverse correlation matrices [1/mm^2]
    K: np.ndarray          #: reference stiffness (29 x 29)
    M: np.ndarray          #: reference mass (29 x 29; singular: massless DOFs)
    influence_dofs: list[int]  #: 1-based DOFs of the ground acceleration (Joint_DOF.xlsx, column Ux)
    sources: dict[str, str] = field(default_factory=dict)

    @property
    def influence(self) -> np.ndarray:
        """The influence vector l (1 on each DOF of ``influence_dofs``)."""
        v = np.zeros(self.K.shape[0])
        v[np.asarray(self.influence_dofs, dtype=int) - 1] = 1.0
        return v


def _need(root: Path, rel: Path) -> Path:
    p = root / rel
    if not p.is_file():
        raise ValueError(f"{p}: file not found (the maRTHS data folder must hold {rel})")
    return p


def _symmetric(a: np.ndarray, where: str) -> None:
    scale = float(np.max(np.abs(a))) if a.size else 0.0
    diff = np.abs(a - a.T)
    if float(np.max(diff)) > SYMMETRY_RTOL * scale:
        i, j = np.unravel_index(int(np.argmax(diff)), a.shape)
        raise ValueError(f"{where}: must be symmetric; entry [{i + 1},{j + 1}] = {a[i, j]:.9g} but "
                         f"[{j + 1},{i + 1}] = {a[j, i]:.9g}")


def _plant(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise ValueError(f"{path}: cannot read this JSON file ({' '.join(str(e).split())})") from None
    if not isinstance(d, dict):
        raise ValueError(f"{path}: expected an object with keys A, B, C, D, got {type(d).__name__}")
    mats = {}
    for k in "ABCD":
        if k not in d:
            raise ValueError(f"{path}: key {k!r} missing (the file holds {sorted(d)})")
        try:
            raw = np.array(d[k], dtype=float)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{path}: {k}: not a numeric matrix ({' '.join(str(e).split())})") from None
        mats[k] = _real_array(raw, f"{path}: {k}", 2)
    A, B, C, D = (mats[k] for k in "ABCD")
    n = A.shape[0]
    if A.shape != (n, n) or n < 1:
        raise ValueError(f"{path}: A must be square, got shape {A.shape}")
    if B.shape != (n, 2):
        raise ValueError(f"{path}: B must be {n} x 2 (states x the two commands), got shape {B.shape}")
    if C.shape != (2, n):
        raise ValueError(f"{path}: C must be 2 x {n} (the two displacements x states), got shape {C.shape}")
    if D.shape != (2, 2):
        raise ValueError(f"{path}: D must be 2 x 2, got shape {D.shape}")
    if np.any(D != 0):
        i, j = np.argwhere(D != 0)[0]
        raise ValueError(f"{path}: D[{i + 1},{j + 1}] = {float(D[i, j])!r}: must be 0 (the identified plant is "
                         "strictly proper)")
    eig = np.linalg.eigvals(A)
    worst = eig[np.argmax(eig.real)]
    if not worst.real < 0:
        raise ValueError(f"{path}: A has the eigenvalue {worst:.6g}: the identified plant must be stable "
                         "(every eigenvalue's real part < 0)")
    return A, B, C, D


def _initial(path: Path) -> tuple[list[np.ndarray], list[np.ndarray]]:
    d = _read_mat(path, ["theta0_1", "theta0_2", "P0_1", "P0_2"])
    thetas, Ps = [], []
    for i in (1, 2):
        th = _real_array(d[f"theta0_{i}"], f"{path}: theta0_{i}", 2)
        if th.ndim != 2 or 1 not in th.shape or not 1 <= th.size <= 8:
            raise ValueError(f"{path}: theta0_{i} must be a vector of 1 to 8 taps, got shape {th.shape}")
        th = th.ravel()
        P = _real_array(d[f"P0_{i}"], f"{path}: P0_{i}", 2)
        if P.shape != (th.size, th.size):
            raise ValueError(f"{path}: P0_{i} must be {th.size} x {th.size} (one row per tap of theta0_{i}), "
                             f"got shape {P.shape}")
        _symmetric(P, f"{path}: P0_{i}")
        low = float(np.min(np.linalg.eigvalsh(0.5 * (P + P.T))))
        if low < -1e-12 * float(np.max(np.abs(P))):
            raise ValueError(f"{path}: P0_{i} must be positive semi-definite (an inverse correlation matrix); its "
                             f"smallest eigenvalue is {low:.6g}")
        thetas.append(th)
        Ps.append(P)
    return thetas, Ps


def read_csv_matrix(path: Path) -> np.ndarray:
    """A numeric matrix from a CSV file as MATLAB's ``csvread``: comma-separated numbers, empty fields
    and the missing ends of short rows are 0.  ValueError naming the file, line and field otherwise."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: cannot read this CSV file ({' '.join(str(e).split())})") from None
    rows = []
    for ln, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        vals = []
        for f in line.split(","):
            f = f.strip()
            if not f:
                vals.append(0.0)
                continue
            try:
                v = float(f)
            except ValueError:
                raise ValueError(f"{path}: line {ln} = {line[:80]!r}: field {f[:30]!r} is not a number") from None
            if not math.isfinite(v):
                raise ValueError(f"{path}: line {ln}: field {f!r} = {v}: must be finite")
            vals.append(v)
        rows.append(vals)
    if not rows:
        raise ValueError(f"{path}: no data rows")
    width = max(len(r) for r in rows)
    return np.array([r + [0.0] * (width - len(r)) for r in rows])


def _structure(path: Path, name: str, size: int | None) -> np.ndarray:
    a = read_csv_matrix(path)
    if a.shape[0] != a.shape[1]:
        raise ValueError(f"{path}: {name} must be square, got shape {a.shape}")
    if size is not None and a.shape[0] != size:
        raise ValueError(f"{path}: {name} must be {size} x {size} (the size of K), got shape {a.shape}")
    if a.shape[0] < MIN_DOFS:
        raise ValueError(f"{path}: {name} must be at least {MIN_DOFS} x {MIN_DOFS} (the benchmark reads and loads "
                         f"DOFs up to {MIN_DOFS}), got shape {a.shape}")
    _symmetric(a, f"{path}: {name}")
    low = float(np.min(np.linalg.eigvalsh(a)))
    tol = 1e-12 * float(np.max(np.abs(a)))
    if name == "K" and not low > tol:
        raise ValueError(f"{path}: K must be positive definite (a restrained structure); its smallest eigenvalue is "
                         f"{low:.6g}")
    if name == "M" and low < -tol:
        raise ValueError(f"{path}: M must be positive semi-definite; its smallest eigenvalue is {low:.6g}")
    return a


_NS = {"x": "http://schemas.openxmlformats.org/spreadsheetml/2006/main"}


def read_influence_dofs(path: Path, size: int) -> list[int]:
    """The nonzero entries of column 2 (``Ux``) of ``Joint_DOF.xlsx``'s first sheet below its header
    (build_reference.m: ``l(l_dof(i, 2)) = 1``), each a DOF 1 .. ``size``."""
    try:
        with zipfile.ZipFile(path) as z:
            names = z.namelist()
            sheet = next((n for n in ("xl/worksheets/sheet1.xml",) if n in names), None)
            if sheet is None:
                raise ValueError(f"{path}: no first worksheet (xl/worksheets/sheet1.xml) in this workbook")
            root = ElementTree.fromstring(z.read(sheet))
    except (zipfile.BadZipFile, OSError, KeyError, ElementTree.ParseError, EOFError) as e:
        raise ValueError(f"{path}: cannot read this Excel file ({type(e).__name__}: "
                         f"{' '.join(str(e).split()) or 'malformed'})") from None
    dofs = []
    for row in root.iterfind(".//x:sheetData/x:row", _NS):
        for c in row.iterfind("x:c", _NS):
            ref = c.get("r", "")
            if re.fullmatch(r"B\d+", ref) is None:
                continue
            v = c.find("x:v", _NS)
            if c.get("t") in ("s", "str", "inlineStr") or v is None:  # the header (text)
                continue
            try:
                x = float(v.text)
            except (TypeError, ValueError):
                raise ValueError(f"{path}: cell {ref} = {v.text!r}: not a number") from None
            if x == 0:
                continue
            if not (x == int(x) and 1 <= x <= size):
                raise ValueError(f"{path}: cell {ref} = {x!r}: must be a DOF number 1 to {size} (or 0)")
            dofs.append(int(x))
    if not dofs:
        raise ValueError(f"{path}: column B (Ux) names no DOF: the ground acceleration would drive nothing")
    return sorted(set(dofs))


def load_data(root: str | Path) -> MarthsData:
    """Every model input of the benchmark from ``root`` (FILES), validated."""
    root = Path(root)
    if not root.is_dir():
        raise ValueError(f"invalid data = {str(root)!r}: not a directory")
    paths = {k: _need(root, rel) for k, rel in FILES.items()}
    A, B, C, D = _plant(paths["plant"])
    theta0, P0 = _initial(paths["initial"])
    K = _structure(paths["K"], "K", None)
    M = _structure(paths["M"], "M", K.shape[0])
    dofs = read_influence_dofs(paths["dofs"], K.shape[0])
    return MarthsData(root, A, B, C, D, theta0, P0, K, M, dofs, sources={k: str(p) for k, p in paths.items()})


def load_record(root: str | Path, name: str) -> Record:
    """A ground-motion record (unscaled) by name (``elcentro``, ``kobe``, ``morgan``)."""
    if name not in RECORDS:
        raise ValueError(f"invalid record = {name!r}: expected one of {sorted(RECORDS)}")
    fname, var = RECORDS[name]
    p = _need(Path(root), Path(fname))
    arr = np.asarray(_read_mat(p, [var])[var])
    if arr.ndim != 2 or arr.shape[0] != 2:
        raise ValueError(f"{p}: variable {var!r} must be 2 rows (time, acceleration), got shape {arr.shape}")
    return check_record(Record(name, arr[0].copy(), arr[1].copy(), source=str(p)))
