"""The RTHS benchmark's inputs: the official data files (read from a folder the
user supplies, never shipped) or an embedded default built from the published
parameters.

Two layouts of the official files are accepted (BENCHMARK.md 1.4): the official
package folder ``RTHS code RT V23/`` (``Building cases/Case_N.mat`` and the
three records at the top level) and a flat folder holding ``Case_N.mat`` and
the records side by side (e.g. ``shared/rths-data/mat/``).  The ``.mat`` files
are read with ``scipy.io.loadmat``; the JSON/CSV copies next to them are read
when a ``.mat`` file is missing.
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["BenchmarkCase", "Record", "RECORDS", "CASES", "load_case", "load_record", "embedded_case",
           "check_case", "check_record",
           "shear_building", "chirp_record",
           "synthetic_record", "reference_stiffness", "modal_damping", "FS", "DT", "EQ_INTENSITY"]

FS = 4096                 #: the benchmark's sample rate [Hz]
DT = 1.0 / FS             #: h = 2**-12 s, exact in binary
EQ_INTENSITY = 0.4        #: records are scaled by this (F1_input_file.m L36)

#: record name -> (.mat file, variable, CSV copy)
RECORDS = {
    "elcentro": ("ElCentroAccelNoScaling.mat", "ElCentroAccel", "elcentro_accel_unscaled.csv"),
    "kobe": ("KobeAccelNoScaling.mat", "KobeAccel", "kobe_accel_unscaled.csv"),
    "morganhill": ("MorganAccelNoScaling.mat", "MorganAccel", "morganhill_accel_unscaled.csv"),
}

#: The four partitioning cases (paper Table 1): floor mass [kg], modal damping of all three modes [-].
CASES = {1: (1000.0, 0.05), 2: (1100.0, 0.04), 3: (1300.0, 0.03), 4: (1000.0, 0.03)}


@dataclass
class BenchmarkCase:
    """A reference structure: 3 lateral DOF, Mr, Cr, Kr [kg, N s/m, N/m]."""
    number: int
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    source: str = ""  #: where it came from (a file, or "embedded")

    @property
    def n(self) -> int:
        return self.M.shape[0]


@dataclass
class Record:
    """An unscaled ground-motion record on its stored time row."""
    name: str
    time: np.ndarray          #: [s]
    acceleration: np.ndarray  #: [m/s^2], unscaled
    source: str = ""
    synthetic: bool = False
    notes: list[str] = field(default_factory=list)

    @property
    def end_time(self) -> float:
        return float(self.time[-1])

    def samples(self, fs: int = FS) -> int:
        """Samples t_k = k/fs, k = 0 .. floor(t_end fs) (BENCHMARK.md 5.4)."""
        return int(math.floor(self.end_time * fs)) + 1


def _first_file(root: Path, names: list[str]) -> Path | None:
    for name in names:
        p = root / name
        if p.is_file():
            return p
    return None


#: Relative asymmetry a structural matrix may have: |A - A^T| <= SYMMETRY_RTOL max|A| (the official
#: cases are symmetric to 2e-16; a file that is not was not written from a structure).
SYMMETRY_RTOL = 1e-9


def _read_mat(path: Path, names: list[str]) -> dict[str, np.ndarray]:
    """The named variables of a MATLAB file; ValueError naming the file (and the variable) otherwise."""
    import scipy.io as sio
    try:
        d = sio.loadmat(str(path))
    except Exception as e:  # noqa: BLE001 - scipy raises many types for a malformed file
        raise ValueError(f"{path}: cannot read this MATLAB file ({type(e).__name__}: "
                         f"{' '.join(str(e).split()) or 'malformed'})") from None
    missing = [n for n in names if n not in d]
    if missing:
        have = sorted(k for k in d if not k.startswith("__"))
        raise ValueError(f"{path}: variable {missing[0]!r} missing (the file holds {have})")
    return {n: d[n] for n in names}


def _real_array(value, where: str, ndim: int) -> np.ndarray:
    """``value`` as a finite real float array of ``ndim`` dimensions; ValueError naming ``where``."""
    a = np.asarray(value)
    if np.iscomplexobj(a):
        raise ValueError(f"{where}: complex values; the benchmark's data are real")
    if a.dtype == object or a.dtype.kind not in "biuf":
        raise ValueError(f"{where}: not a numeric array (dtype {a.dtype})")
    a = a.astype(float)
    if a.ndim != ndim:
        raise ValueError(f"{where}: expected a {ndim}-D array, got shape {a.shape}")
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        i = tuple(int(v) for v in bad[0])
        raise ValueError(f"{where}: entry {list(i)} = {a[i]}: must be finite")
    return a


def check_case(case: BenchmarkCase) -> BenchmarkCase:
    """Validates a case: M, C, K real, finite, square, of one size, symmetric; M and K positive
    definite; C positive semi-definite.  ValueError naming the source and the matrix otherwise."""
    mats = {}
    for name in ("M", "C", "K"):
        a = _real_array(getattr(case, name), f"{case.source}: {name}", 2)
        if a.shape[0] != a.shape[1] or a.shape[0] < 1:
            raise ValueError(f"{case.source}: {name} must be square, got shape {a.shape}")
        scale = float(np.max(np.abs(a)))
        asym = float(np.max(np.abs(a - a.T)))
        if asym > SYMMETRY_RTOL * scale:
            i, j = np.unravel_index(int(np.argmax(np.abs(a - a.T))), a.shape)
            raise ValueError(f"{case.source}: {name} must be symmetric; {name}[{i},{j}] = {a[i, j]:.9g} but "
                             f"{name}[{j},{i}] = {a[j, i]:.9g}")
        mats[name] = a
    shapes = {n: a.shape for n, a in mats.items()}
    if len(set(shapes.values())) != 1:
        raise ValueError(f"{case.source}: M, C and K must have one size, got {shapes}")
    for name, definite in (("M", True), ("K", True), ("C", False)):
        a = mats[name]
        low = float(np.min(np.linalg.eigvalsh(0.5 * (a + a.T))))
        tol = 1e-12 * float(np.max(np.abs(a)))
        if (definite and not low > tol) or (not definite and low < -tol * 1e3):
            need = "positive definite" if definite else "positive semi-definite"
            raise ValueError(f"{case.source}: {name} must be {need}; its smallest eigenvalue is {low:.6g}")
    case.M, case.C, case.K = mats["M"], mats["C"], mats["K"]
    return case


def check_record(rec: Record) -> Record:
    """Validates a record: finite, real, 1-D, of one length, on a uniform increasing time row."""
    from ..timegrid import uniform_dt

    t = _real_array(rec.time, f"{rec.source}: time", 1)
    a = _real_array(rec.acceleration, f"{rec.source}: acceleration", 1)
    if t.size != a.size:
        raise ValueError(f"{rec.source}: time has {t.size} samples but acceleration {a.size}")
    uniform_dt(t, f"{rec.source}: time")
    rec.time, rec.acceleration = t, a
    return rec


def load_case(root: str | Path, number: int) -> BenchmarkCase:
    """Case N from the official ``Case_N.mat`` (either layout) or ``building_cases.json``."""
    if number not in CASES:
        raise ValueError(f"invalid case = {number!r}: expected one of 1, 2, 3, 4")
    root = Path(root)
    if not root.is_dir():
        raise ValueError(f"invalid data = {str(root)!r}: not a directory")
    p = _first_file(root, [f"Building cases/Case_{number}.mat", f"Case_{number}.mat"])
    if p is not None:
        d = _read_mat(p, ["M", "C", "K"])  # sys_r (an ss object) is opaque to scipy: rebuilt from M, C, K
        return check_case(BenchmarkCase(number, d["M"], d["C"], d["K"], source=str(p)))
    j = _first_file(root, ["building_cases.json", "../building_cases.json"])
    if j is not None:
        try:
            c = json.loads(j.read_text(encoding="utf-8"))["cases"][f"case_{number}"]
            mats = [c[n] for n in ("M", "C", "K")]
        except (OSError, UnicodeDecodeError, ValueError) as e:
            raise ValueError(f"{j}: cannot read this JSON file ({' '.join(str(e).split())})") from None
        except (KeyError, TypeError) as e:
            raise ValueError(f"{j}: no cases.case_{number} with M, C and K ({type(e).__name__}: {e})") from None
        arrays = []
        for n, m in zip("MCK", mats):
            try:
                arrays.append(np.array(m))
            except ValueError as e:  # ragged rows
                raise ValueError(f"{j}: cases.case_{number}.{n}: not a matrix ({' '.join(str(e).split())})") from None
        return check_case(BenchmarkCase(number, *arrays, source=f"{j} (cases.case_{number})"))
    raise ValueError(f"invalid data = {str(root)!r}: Case_{number}.mat not found (neither "
                     "'Building cases/Case_N.mat' nor 'Case_N.mat' nor building_cases.json)")


def load_record(root: str | Path | None, name: str) -> Record:
    """An official record (``*AccelNoScaling.mat`` or its CSV copy), unscaled; ``"chirp"``:
    the benchmark's verification chirp (``chirp_record``, generated, no file needed)."""
    if name == "chirp":
        return chirp_record()
    if name not in RECORDS:
        raise ValueError(f"invalid record = {name!r}: expected one of {sorted(RECORDS) + ['chirp']}")
    root = Path(root)
    fname, var, csv_name = RECORDS[name]
    p = _first_file(root, [fname])
    if p is not None:
        arr = np.asarray(_read_mat(p, [var])[var])
        if arr.ndim != 2 or arr.shape[0] != 2:
            raise ValueError(f"{p}: variable {var!r} must be 2 rows (time, acceleration), got shape {arr.shape}")
        return check_record(Record(name, arr[0].copy(), arr[1].copy(), source=str(p)))
    c = _first_file(root, [csv_name, f"../{csv_name}"])
    if c is not None:
        return check_record(Record(name, *_read_csv(c), source=str(c)))
    raise ValueError(f"invalid data = {str(root)!r}: {fname} not found")


def _read_csv(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(time, acceleration) of a record's CSV copy (a header row, then two numbers a row)."""
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise ValueError(f"{path}: cannot read this CSV file ({' '.join(str(e).split())})") from None
    values = []
    for i, r in enumerate(rows[1:], start=2):
        try:
            t, a = (float(v) for v in r)
        except ValueError:
            raise ValueError(f"{path}: line {i} = {','.join(r)[:80]!r}: expected two numbers "
                             "(time, acceleration)") from None
        values.append((t, a))
    if not values:
        raise ValueError(f"{path}: no data rows")
    arr = np.array(values)
    return arr[:, 0].copy(), arr[:, 1].copy()


# ----------------------------------------------------------------------------- embedded default

def reference_stiffness(E: float = 200e9, Ic: float = 2.520 * 0.0254**4, Ib: float = 255267e-12,
                        H: float = 0.635, L: float = 0.762) -> np.ndarray:
    """The 3-DOF lateral stiffness of the frame by static condensation of the
    12-DOF matrix of KK_mat.m (BENCHMARK.md 4.2; paper Sec 2.3) [N/m]."""
    c3, c2, c1, b1 = Ic / H**3, Ic / H**2, Ic / H, Ib / L
    KK = np.zeros((12, 12))
    KK[np.arange(12), np.arange(12)] = [45 * c3, 72 * c3, 36 * c3, 7 * c1 + 4 * b1, 7 * c1 + 8 * b1, 7 * c1 + 4 * b1,
                                        8 * c1 + 4 * b1, 8 * c1 + 8 * b1, 8 * c1 + 4 * b1, 4 * c1 + 4 * b1,
                                        4 * c1 + 8 * b1, 4 * c1 + 4 * b1]
    upper = {0: (1, [-36 * c3, 0, -3 * c2, -3 * c2, -3 * c2, -6 * c2, -6 * c2, -6 * c2, 0, 0, 0]),
             1: (2, [-36 * c3, 6 * c2, 6 * c2, 6 * c2, 0, 0, 0, -6 * c2, -6 * c2, -6 * c2]),
             2: (3, [0, 0, 0, 6 * c2, 6 * c2, 6 * c2, 6 * c2, 6 * c2, 6 * c2]),
             3: (4, [2 * b1, 0, 2 * c1, 0, 0, 0, 0, 0]),
             4: (5, [2 * b1, 0, 2 * c1, 0, 0, 0, 0]),
             5: (6, [0, 0, 2 * c1, 0, 0, 0]),
             6: (7, [2 * b1, 0, 2 * c1, 0, 0]),
             7: (8, [2 * b1, 0, 2 * c1, 0]),
             8: (9, [0, 0, 2 * c1]),
             9: (10, [2 * b1, 0]),
             10: (11, [2 * b1])}
    for row, (col0, vals) in upper.items():
        KK[row, col0:col0 + len(vals)] = vals
    KK = np.triu(KK) + np.triu(KK, 1).T
    KK *= E
    k11, k21, k22 = KK[:3, :3], KK[3:, :3], KK[3:, 3:]
    return k11 - k21.T @ np.linalg.solve(k22, k21)


def modal_damping(M: np.ndarray, K: np.ndarray, zetas) -> np.ndarray:
    """C from modal damping with omega rounded to 0.01 rad/s (modes.m, CC_mat.m)."""
    w2, fi = np.linalg.eig(np.linalg.solve(M, K))
    order = np.argsort(w2.real)
    w2, fi = w2.real[order], fi.real[:, order]
    w = np.round(100.0 * np.sqrt(w2)) / 100.0  # positive values: numpy's round ties never matter here
    Mn = np.einsum("ij,ik,kj->j", fi, M, fi)
    fiT_inv = np.linalg.inv(fi.T)
    return fiT_inv @ np.diag(2.0 * np.asarray(zetas) * w * Mn) @ np.linalg.inv(fi)


def embedded_case(number: int) -> BenchmarkCase:
    """Case N rebuilt from the published parameters (paper Table 1, Sec 2; BENCHMARK.md 4)."""
    if number not in CASES:
        raise ValueError(f"invalid case = {number!r}: expected one of 1, 2, 3, 4")
    m, zeta = CASES[number]
    M = m * np.eye(3)
    K = reference_stiffness()
    return BenchmarkCase(number, M, modal_damping(M, K, [zeta] * 3), K, source="embedded (published parameters)")


def chirp_record(f1: float = 0.1, f2: float = 40.0, T: float = 90.0) -> Record:
    """The benchmark's chirp (E_sw = 4; BENCHMARK.md 6): unit amplitude (scaled by eq_intensity
    like the records), sin(2 pi (f1 t + (f2 - f1) t^2 / (2 T))), t = 0 .. T, no zero padding.
    Sampled every h/2 = 2^-13 s, so that the loop's linear interpolation at the RK4 stage times
    t_k, t_k + h/2, t_k + h returns the exact sine.  The paper publishes no chirp results."""
    for name, v in (("f1", f1), ("f2", f2), ("T", T)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
            raise ValueError(f"invalid {name} = {v!r}: finite and >= 0")
    if not T > 0:
        raise ValueError(f"invalid T = {T!r}: > 0 [s]")
    t = np.arange(int(math.floor(T * 2 * FS)) + 1) * (DT / 2)
    a = np.sin(2 * np.pi * (f1 * t + (f2 - f1) * t * t / (2 * T)))
    return Record("chirp", t, a, source=f"generated: linear chirp {f1:g}-{f2:g} Hz over {T:g} s (BENCHMARK.md 6)",
                  notes=["the benchmark's verification chirp: no published results"])


def shear_building(storey_stiffness=(6e6, 5e6, 4e6), floor_mass: float = 1000.0,
                   zeta: float = 0.05) -> BenchmarkCase:
    """A shear building (NOT one of the benchmark's cases) as a BenchmarkCase: storey
    stiffnesses [N/m] from the ground up, equal floor masses [kg], Rayleigh damping C = a M + b K
    with ``zeta`` at the first and last modes.  Its stiffness splits into positive storey springs,
    so a storey can be made to yield (rths.spring_model)."""
    ks = np.asarray(storey_stiffness, dtype=float)
    n = ks.size
    if n < 1 or not np.all(np.isfinite(ks)) or np.any(ks <= 0):
        raise ValueError(f"invalid storey_stiffness = {ks.tolist()}: finite and > 0 [N/m]")
    if not (math.isfinite(floor_mass) and floor_mass > 0 and math.isfinite(zeta) and zeta >= 0):
        raise ValueError(f"invalid floor_mass, zeta = {floor_mass!r}, {zeta!r}: > 0 [kg], >= 0")
    K = np.diag(ks + np.append(ks[1:], 0.0)) - np.diag(ks[1:], 1) - np.diag(ks[1:], -1)
    M = floor_mass * np.eye(n)
    w = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    a, b = (zeta * w[0], 0.0) if n == 1 else np.linalg.solve([[1 / (2 * w[0]), w[0] / 2],
                                                                [1 / (2 * w[-1]), w[-1] / 2]], [zeta, zeta])
    return BenchmarkCase(0, M, a * M + b * K, K, source=f"shear building {ks.tolist()} N/m (Rayleigh {a:.6g}, {b:.6g})")


def synthetic_record(duration: float = 20.0, dt: float = 0.01, pga: float = 3.0, seed: int = 1) -> Record:
    """A synthetic ground motion (NOT one of the benchmark's records): filtered
    white noise (Kanai-Tajimi, omega_g = 15 rad/s, zeta_g = 0.6) under a
    Jennings-type envelope, scaled to ``pga`` [m/s^2], padded with 5 s of zeros
    at each end as the benchmark's records."""
    from scipy import signal
    rng = np.random.default_rng(seed)
    n = int(round(duration / dt))
    w = rng.standard_normal(n)
    wg, zg = 15.0, 0.6
    num, den = signal.bilinear([2 * zg * wg, wg**2], [1.0, 2 * zg * wg, wg**2], fs=1.0 / dt)
    a = signal.lfilter(num, den, w)
    t = np.arange(n) * dt
    env = np.clip(t / 2.0, 0, 1) ** 2 * np.where(t > 0.6 * duration, np.exp(-(t - 0.6 * duration) / 3.0), 1.0)
    a *= env
    a *= pga / np.max(np.abs(a))
    pad = int(round(5.0 / dt))
    acc = np.concatenate([np.zeros(pad), a, np.zeros(pad)])
    time = np.arange(acc.size) * dt
    return Record("synthetic", time, acc, source=f"synthetic (seed {seed})", synthetic=True,
                  notes=["synthetic ground motion: NOT one of the benchmark's records"])
