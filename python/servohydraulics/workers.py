"""Process pools of the package (``sweep``, ``reproduce``, ``rths-benchmark``):
worker counts bounded to the machine, workers that die with their parent.

``check_workers(n)`` accepts 1 .. ``os.cpu_count()`` (more processes than cores
only queue; a count such as 100000 forks until the machine stops) and raises a
ValueError naming the field and the value otherwise.  ``process_pool(n)`` is a
``ProcessPoolExecutor`` whose workers ask Linux (``prctl(PR_SET_PDEATHSIG)``)
to be sent SIGKILL when the process that started them dies, so a killed run
(SIGKILL, the OOM killer) leaves no orphan computing for nobody.

``blas_threads(1)`` holds the OpenBLAS libraries loaded in the process (numpy's and scipy's
wheels bundle one each) at one thread while ``sh.identify`` and ``sh.diagnose`` simulate on their
own threads: OpenBLAS's idle workers spin after each call, on the cores the simulations need.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager

_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def cpu_count() -> int:
    """The machine's logical processors (at least 1)."""
    return os.cpu_count() or 1


def check_workers(value, name: str = "workers") -> int:
    """``value`` as an int in 1 .. cpu_count(); ValueError naming ``name`` and the value otherwise."""
    n = cpu_count()
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= n:
        raise ValueError(f"invalid {name} = {value!r}: must be an integer from 1 to {n} (this machine's processors)")
    return value


def default_workers(cap: int | None = None) -> int:
    """All processors, or at most ``cap`` of them."""
    n = cpu_count()
    return n if cap is None else max(1, min(cap, n))


def _die_with_parent(parent: int) -> None:
    """Pool initializer: SIGKILL this worker when its parent dies (Linux; elsewhere a no-op)."""
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # no prctl: the pool's own broken-pipe detection remains
            return
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)


def process_pool(workers: int, name: str = "workers") -> ProcessPoolExecutor:
    """A ``ProcessPoolExecutor`` of ``check_workers(workers)`` processes that die with this one.

    Linux delivers the death signal when the *thread* that forked the worker
    ends; submit from a thread that lives as long as the pool (the main thread
    of a command does)."""
    return ProcessPoolExecutor(max_workers=check_workers(workers, name), initializer=_die_with_parent,
                               initargs=(os.getpid(),))


__all__ = ["check_workers", "cpu_count", "default_workers", "process_pool"]


#: (getter, setter) symbol pairs of OpenBLAS builds: the numpy and scipy wheels' (ILP64 and LP64), a plain one
_OPENBLAS_SYMBOLS = (("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
                     ("scipy_openblas_get_num_threads", "scipy_openblas_set_num_threads"),
                     ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
                     ("openblas_get_num_threads", "openblas_set_num_threads"))


def _openblas() -> list:
    """(get, set) thread-count functions of each OpenBLAS library loaded in this process (Linux:
    the shared objects /proc/self/maps lists); empty elsewhere or for other BLAS libraries."""
    try:
        with open("/proc/self/maps") as f:
            paths = sorted({line.split()[-1] for line in f if "openblas" in line.lower()
                            and line.split()[-1].startswith("/")})
    except OSError:
        return []
    out = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)  # already loaded: the same handle
        except OSError:
            continue
        for get, put in _OPENBLAS_SYMBOLS:
            if hasattr(lib, get) and hasattr(lib, put):
                out.append((getattr(lib, get), getattr(lib, put)))
                break
    return out


@contextmanager
def blas_threads(n: int = 1):
    """Holds every loaded OpenBLAS library at ``n`` threads inside the block, its own count restored
    after (nothing where none is loaded or the BLAS is another)."""
    libs = _openblas()
    old = [int(get()) for get, _ in libs]
    for _, put in libs:
        put(int(n))
    try:
        yield
    finally:
        for (_, put), m in zip(libs, old):
            put(m)


def single_blas_thread(fn):
    """``fn`` run inside ``blas_threads(1)`` (``sh.identify``, ``sh.diagnose``)."""
    import functools

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with blas_threads(1):
            return fn(*args, **kwargs)
    return wrapper
