"""Process pools of the package (``sweep``, ``reproduce``, ``rths-benchmark``):
worker counts bounded to the machine, workers that die with their parent.

``check_workers(n)`` accepts 1 .. ``os.cpu_count()`` (more processes than cores
only queue; a count such as 100000 forks until the machine stops) and raises a
ValueError naming the field and the value otherwise.  ``process_pool(n)`` is a
``ProcessPoolExecutor`` whose workers ask Linux (``prctl(PR_SET_PDEATHSIG)``)
to be sent SIGKILL when the process that started them dies, so a killed run
(SIGKILL, the OOM killer) leaves no orphan computing for nobody.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
from concurrent.futures import ProcessPoolExecutor

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
