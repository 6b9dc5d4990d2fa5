"""MATLAB ``.mat`` records: variables by name.

What is read (docs/lab-records.md, "Record files"):

* **separate vectors**: ``time``, ``command``, ``displacement``, ``force`` (or any names,
  mapped with ``--columns command=u_cmd``), each n x 1, 1 x n or n;
* **a struct**: its fields, addressed as ``rec.force`` (nested: ``test.rec.force``); a field
  named like a channel is found by itself;
* **a matrix with named columns**: a matrix ``M`` (samples along its longer dimension) with
  its column names in a cell array of strings beside it (``M_names``, ``M_columns``,
  ``M_labels``, or ``names``/``columns``/``labels``/``channels``/``colheaders`` when it is the
  only matrix there: MATLAB's ``importdata`` gives a struct of ``data`` and ``colheaders``):
  the columns are ``M.force`` etc.; any matrix's k-th channel is ``M(:,k)`` (1-based);
* scalars (``dt``, ``fs``, a current) are metadata: ``dt``/``Ts`` [s] or ``fs``/``Fs`` [Hz]
  give the sample interval of a record without a time vector.

Version 5 to 7 files through ``scipy.io.loadmat``; version 7.3 (HDF5) through ``h5py`` when
it is installed (``pip install h5py``), else an error that says so.  A MATLAB ``table`` or
class object is opaque to both: save it as a struct (``table2struct(T, 'ToScalar', true)``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: names of a cell array holding a matrix's column names (beside the matrix)
NAME_LISTS = ("names", "columns", "labels", "channels", "colheaders", "headers", "header")
#: scalars read as the sample interval [s] or rate [Hz]
INTERVAL_NAMES, RATE_NAMES = ("dt", "Ts", "ts", "sample_interval"), ("fs", "Fs", "sample_rate", "sampling_rate")
_INDEX = re.compile(r"^(.+?)\s*\(\s*:\s*,\s*(\d+)\s*\)$")


@dataclass(eq=False)
class MatSource:
    """The numeric vectors of a .mat file by name, its scalars and what else it holds."""

    path: Path
    vectors: dict = field(default_factory=dict)  #: name -> 1-D array (``x``, ``s.x``, ``M.name``)
    matrices: dict = field(default_factory=dict)  #: name -> 2-D array, samples along axis 0
    scalars: dict = field(default_factory=dict)  #: name -> float
    other: dict = field(default_factory=dict)  #: name -> what it is (not read)
    version: str = "5"

    @property
    def header(self) -> list[str]:
        return list(self.vectors)

    def describe(self) -> str:
        parts = [f"{k} ({v.size})" for k, v in self.vectors.items()]
        parts += [f"{k} ({v.shape[0]} x {v.shape[1]}: {k}(:,1) .. {k}(:,{v.shape[1]}))"
                  for k, v in self.matrices.items()]
        parts += [f"{k} = {v:g}" for k, v in self.scalars.items()]
        parts += [f"{k} ({v})" for k, v in self.other.items()]
        return f"variables: {', '.join(parts) or 'none'} (MATLAB v{self.version})"

    def get(self, name: str) -> np.ndarray | None:
        """A vector by name, or ``M(:,k)``: the k-th channel of matrix M (1-based)."""
        if name in self.vectors:
            return self.vectors[name]
        m = _INDEX.match(name.strip())
        if m and m.group(1) in self.matrices:
            mat, k = self.matrices[m.group(1)], int(m.group(2))
            if not 1 <= k <= mat.shape[1]:
                raise ValueError(f"{self.path}: invalid column {name!r}: {m.group(1)} has {mat.shape[1]} "
                                 f"channel(s) ({mat.shape[0]} x {mat.shape[1]})")
            return mat[:, k - 1]
        return None


def _samples_first(a: np.ndarray) -> np.ndarray:
    return a.T if a.shape[0] < a.shape[1] else a


def _strings(obj) -> list[str] | None:
    """A list of strings from a cell array of char (scipy: a list, an object array or a str array)."""
    if isinstance(obj, str):
        return None
    try:
        items = list(np.asarray(obj, dtype=object).ravel())
    except Exception:  # noqa: BLE001 - anything that is not a list of strings
        return None
    if items and all(isinstance(s, str) for s in items):
        return [s.strip() for s in items]
    return None


def _walk(src: MatSource, prefix: str, items: dict) -> None:
    """Files the variables of one level (top level or a struct's fields)."""
    names = {k: _strings(v) for k, v in items.items() if not isinstance(v, dict)}
    matrices = [k for k, v in items.items() if isinstance(v, np.ndarray) and v.dtype.kind in "fiub" and v.ndim == 2
                and min(v.shape) > 1]
    for key, v in items.items():
        name = f"{prefix}{key}"
        if isinstance(v, dict):
            _walk(src, name + ".", v)
        elif isinstance(v, np.ndarray) and v.dtype.kind in "fiub":
            a = np.asarray(v, dtype=float)
            if a.size == 1:
                src.scalars[name] = float(a.ravel()[0])
            elif a.ndim == 1 or (a.ndim == 2 and min(a.shape) == 1):
                src.vectors[name] = a.ravel()
            elif a.ndim == 2:
                mat = _samples_first(a)
                src.matrices[name] = mat
                labels = next((names.get(f"{key}_{s}") for s in NAME_LISTS if names.get(f"{key}_{s}")), None)
                if labels is None and len(matrices) == 1:
                    labels = next((names[s] for s in NAME_LISTS if names.get(s)), None)
                if labels is not None and len(labels) == mat.shape[1]:
                    for j, lab in enumerate(labels):
                        src.vectors[f"{name}.{lab}"] = mat[:, j]
            else:
                src.other[name] = f"{a.ndim}-D array {a.shape}"
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            src.scalars[name] = float(v)
        elif isinstance(v, str):
            src.other[name] = f"text {v[:30]!r}"
        elif names.get(key) is not None:
            src.other[name] = f"{len(names[key])} names"
        else:
            kind = type(v).__name__
            src.other[name] = ("an opaque MATLAB object (a table or a class: save it as a struct, "
                               "table2struct(T, 'ToScalar', true))" if "Opaque" in kind or "Function" in kind
                               else kind)


def read_mat(path: Path) -> MatSource:
    """Reads a .mat file's variables (see the module docstring); ValueError naming the file."""
    with open(path, "rb") as f:
        head = f.read(128)
    if head.startswith(b"MATLAB 7.3 MAT-file") or head[:8] == b"\x89HDF\r\n\x1a\n":
        return _read_hdf5(path)
    if len(head) < 128 or not head.startswith(b"MATLAB"):
        raise ValueError(f"{path}: not a MATLAB .mat file (no 'MATLAB ... MAT-file' header; MATLAB v4 files are "
                         "not read: save it with save(..., '-v7'))")
    from scipy.io import loadmat

    try:
        data = loadmat(path, squeeze_me=True, simplify_cells=True)
    except NotImplementedError:
        return _read_hdf5(path)
    except Exception as e:  # noqa: BLE001 - scipy raises many kinds on a damaged file
        raise ValueError(f"{path}: cannot read the .mat file ({type(e).__name__}: {e})") from None
    src = MatSource(path=path, version=head[7:10].decode("ascii", "replace").strip() or "5")
    _walk(src, "", {k: v for k, v in data.items() if not k.startswith("__")})
    return src


def _read_hdf5(path: Path) -> MatSource:
    try:
        import h5py
    except ImportError:
        raise ValueError(f"{path}: a MATLAB v7.3 (HDF5) file: reading it needs h5py (pip install h5py), or save "
                         "it in MATLAB with save(FILE, VARS..., '-v7')") from None
    src = MatSource(path=path, version="7.3")
    try:
        with h5py.File(path, "r") as f:
            _walk(src, "", {k: _h5_value(f, f[k]) for k in f if not k.startswith("#")})
    except OSError as e:
        raise ValueError(f"{path}: cannot read the v7.3 (HDF5) .mat file: {e}") from None
    return src


def _h5_value(f, obj):
    """A v7.3 variable as scipy would give it: arrays (MATLAB's column-major order undone),
    dicts for structs, lists of strings for cell arrays of char, str for char arrays."""
    import h5py

    if isinstance(obj, h5py.Group):
        return {k: _h5_value(f, obj[k]) for k in obj}
    cls = obj.attrs.get("MATLAB_class", b"")
    cls = cls.decode() if isinstance(cls, bytes) else str(cls)
    if obj.attrs.get("MATLAB_empty", 0):
        return np.zeros(0)
    data = obj[()]
    if cls == "char":
        return "".join(chr(c) for c in np.asarray(data).T.ravel())
    if cls == "cell":
        return [_h5_value(f, f[ref]) for ref in np.asarray(data).T.ravel()]
    arr = np.asarray(data)
    return arr.T if arr.ndim >= 2 else arr


def sample_interval(src: MatSource) -> float | None:
    """The sample interval [s] a scalar of the file gives (``dt``/``Ts``, or 1/``fs``), or None."""
    for n in INTERVAL_NAMES:
        if n in src.scalars:
            return src.scalars[n]
    for n in RATE_NAMES:
        if n in src.scalars and src.scalars[n] != 0:
            return 1.0 / src.scalars[n]
    return None


__all__ = ["MatSource", "read_mat", "sample_interval"]
