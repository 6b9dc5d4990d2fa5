"""Pacing a loop to the wall clock, one sample per period (the C++ core's
``servohydraulics/realtime.hpp``), measured the way ``cyclictest`` measures it.

    from servohydraulics.realtime import Pacer
    pacer = Pacer(1 / 4096, fifo_priority=80, cpu=1, lock_memory=True)
    pacer.start()                     # first deadline = now + period
    for k in range(n):
        pacer.wait()                  # sleeps to deadline k (CLOCK_MONOTONIC, TIMER_ABSTIME)
        step()
    pacer.stats()                     # samples, misses, latency/compute percentiles [us], what was permitted
    pacer.stop()                      # the thread's policy and affinity as before start()

or ``with Pacer(...) as pacer:`` (start on entry, stop on exit).

Deadline k is ``start + k * period`` exactly (no drift).  A loop that falls
behind runs its samples back to back until it has caught up (none is dropped);
every ``wait()`` entered after its deadline is a deadline miss.  ``wait()``
returns the wake-up latency [s] (>= 0), releases the GIL while it sleeps and
records, allocation-free, the latency and the compute time of the step before
it (from the previous ``wait()``'s return to this call, which includes taking
the GIL back).  SCHED_FIFO, mlockall and CPU pinning are requests; a refusal
never fails the run and ``stats()`` gives its reason (the errno).
"""

from __future__ import annotations

from . import _core

#: The percentiles of ``stats()["latency_us"]`` and ``["compute_us"]``, in this order.
PERCENTILES = ("min", "p50", "p99", "p99.9", "max")


def monotonic_ns() -> int:
    """CLOCK_MONOTONIC [ns], the clock of the deadlines (``time.monotonic_ns()`` reads it too)."""
    return _core.monotonic_ns()


def _percentiles(p) -> dict:
    return {"min": p.min, "p50": p.p50, "p99": p.p99, "p99.9": p.p999, "max": p.max, "mean": p.mean}


class Pacer:
    """One sample per ``period_s`` on absolute CLOCK_MONOTONIC deadlines.

    ``fifo_priority`` (1..99) asks for SCHED_FIFO for the thread that calls
    ``start()``; ``cpu`` pins that thread to one CPU; ``lock_memory`` calls
    ``mlockall(MCL_CURRENT | MCL_FUTURE)``.  Bad values raise ``ValueError``
    naming the field: a period outside [1e-6, 60] s, a priority outside the
    system's SCHED_FIFO range, a CPU the machine does not have.
    """

    def __init__(self, period_s: float, *, fifo_priority: int | None = None, cpu: int | None = None,
                 lock_memory: bool = False) -> None:
        for name, value in (("fifo_priority", fifo_priority), ("cpu", cpu)):
            if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
                raise ValueError(f"invalid {name} = {value!r}: an integer (or None: do not ask)")
        if fifo_priority == 0:
            raise ValueError("invalid fifo_priority = 0: SCHED_FIFO priorities start at 1 (None: do not ask)")
        if cpu is not None and cpu < 0:
            raise ValueError(f"invalid cpu = {cpu}: a CPU number >= 0 (None: do not pin)")
        try:
            period = float(period_s)
        except (TypeError, ValueError):
            raise ValueError(f"invalid period_s = {period_s!r}: a number of seconds") from None
        self._pacer = _core.Pacer(period, fifo_priority=fifo_priority or 0,
                                  cpu=-1 if cpu is None else cpu, lock_memory=bool(lock_memory))

    # -- the loop --------------------------------------------------------------
    def start(self) -> Pacer:
        """Applies the requests to the calling thread and starts the schedule
        (deadline 1 = now + period).  Again: restarts the schedule and the statistics."""
        self._pacer.start()
        return self

    def wait(self) -> float:
        """Sleeps to the next deadline; returns the wake-up latency [s] (>= 0).
        Raises ``RuntimeError`` before ``start()``."""
        late = self._pacer.wait()
        if late < 0.0:
            raise RuntimeError("Pacer.wait() before start(): start the schedule first (or use 'with Pacer(...)')")
        return late

    def stop(self) -> None:
        """Restores the calling thread's policy and affinity (and unlocks memory).
        Call it on the thread that called ``start()``; the statistics stay."""
        self._pacer.stop()

    def __enter__(self) -> Pacer:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    # -- the schedule ----------------------------------------------------------
    @property
    def period_s(self) -> float:
        return self._pacer.period_s

    @property
    def start_ns(self) -> int:
        """CLOCK_MONOTONIC of ``start()`` [ns]."""
        return self._pacer.start_ns

    def deadline_ns(self, k: int) -> int:
        """Deadline ``k`` [ns]: ``start_ns + round(k * period)``."""
        return self._pacer.deadline_ns(k)

    @property
    def samples(self) -> int:
        return self._pacer.samples

    @property
    def misses(self) -> int:
        return self._pacer.misses

    # -- the figures -----------------------------------------------------------
    def stats(self) -> dict:
        """The run so far, JSON-ready::

            {"period_s", "samples", "misses",
             "latency_us": {"min", "p50", "p99", "p99.9", "max", "mean"},   # wake-up latency
             "compute_us": {...same...},                                      # the step between two waits
             "fifo": bool, "fifo_reason": str,
             "mlockall": bool, "mlockall_reason": str,
             "cpu_affinity": bool, "cpu_affinity_reason": str}

        Percentiles are nearest-rank from a histogram whose bins are at most
        1/64 of their value wide (1 ns below 64 ns); min, max and mean are exact.
        A ``*_reason`` is "not requested", "granted: ..." or the refusal with its errno.
        """
        s = self._pacer.stats()
        out = {"period_s": s.period_s, "samples": s.samples, "misses": s.misses,
               "latency_us": _percentiles(s.latency_us), "compute_us": _percentiles(s.compute_us)}
        for name in ("fifo", "mlockall", "cpu_affinity"):
            p = getattr(s, name)
            out[name] = p.granted
            out[f"{name}_reason"] = p.reason
        return out

    def __repr__(self) -> str:
        return (f"Pacer(period_s={self.period_s!r}, samples={self.samples}, misses={self.misses}, "
                f"started={self._pacer.started})")
