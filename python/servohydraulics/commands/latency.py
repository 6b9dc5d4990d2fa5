"""``servohydraulics latency``: how well this machine paces a loop to the wall clock.

    servohydraulics latency --rate 4096 --seconds 10 [--fifo 80] [--cpu 1] [--mlock] [--plant] [--json out.json]

One sample per period on absolute CLOCK_MONOTONIC deadlines (``realtime.Pacer``),
cyclictest style: the wake-up latency (deadline to return of the sleep) and,
with ``--plant``, the compute time of one step of the paper's plant (Zhao 2003,
displacement control, a 1 Hz 10 mm sine, one sample per period) in the loop,
as percentiles [us], with the deadline misses and what the system permitted.
"""

from __future__ import annotations

import gc
import json
import math

#: Longest run [s]: a measurement, not a soak.
MAX_SECONDS = 3600.0


def check_rate(rate: float) -> float:
    """The loop rate [Hz]: finite, 1/60 .. 1e6 (the Pacer's period range)."""
    if not (isinstance(rate, (int, float)) and math.isfinite(rate) and 1.0 / 60.0 <= rate <= 1e6):
        raise ValueError(f"invalid --rate = {rate!r}: the loop rate in Hz, within [1/60, 1e6]")
    return float(rate)


def check_seconds(seconds: float, rate: float) -> float:
    if not (isinstance(seconds, (int, float)) and math.isfinite(seconds) and 0 < seconds <= MAX_SECONDS):
        raise ValueError(f"invalid --seconds = {seconds!r}: the run length, within (0, {MAX_SECONDS:g}] s")
    if seconds * rate < 1.0:
        raise ValueError(f"invalid --seconds = {seconds!r}: shorter than one period at --rate {rate:g} Hz")
    return float(seconds)


def measure(rate: float, seconds: float, *, fifo: int | None = None, cpu: int | None = None,
            mlock: bool = False, plant: bool = False) -> dict:
    """Runs the paced loop for ``seconds`` at ``rate`` (Python's garbage collector
    paused meanwhile) and returns ``Pacer.stats()`` with ``rate_hz``, ``seconds``
    and ``step`` ("plant" or "none") added."""
    from ..realtime import Pacer

    rate = check_rate(rate)
    seconds = check_seconds(seconds, rate)
    n = int(round(seconds * rate))
    pacer = Pacer(1.0 / rate, fifo_priority=fifo, cpu=cpu, lock_memory=mlock)
    step = _plant_step(1.0 / rate) if plant else None
    failures = 0
    collecting = gc.isenabled()
    gc.disable()  # no collection pauses inside the loop (the loop allocates little; collected after)
    pacer.start()
    try:
        if step is None:
            for _ in range(n):
                pacer.wait()
        else:
            for k in range(n):
                pacer.wait()
                failures += not step(k)
    finally:
        pacer.stop()
        if collecting:
            gc.enable()
    out = pacer.stats()
    out.update(rate_hz=rate, seconds=seconds, step="plant" if plant else "none")
    if plant:
        out["plant_failures"] = failures
    return out


def _plant_step(dt: float):
    """step(k) -> ok: one sample of the paper's plant under a 1 Hz, 10 mm sine command."""
    from ..rig import zhao2003
    from ..simulate import make_plant

    plant = make_plant(zhao2003(), "displacement", dt=dt)
    w = 2.0 * math.pi * 1.0

    def step(k: int) -> bool:
        status, _ = plant.step(0.01 * math.sin(w * k * dt))
        if status.ok():
            return True
        plant.reset(0.0, plant.time)
        return False

    return step


def table(rows: list[dict]) -> str:
    """A Markdown table of measure() results, one row each (misses and compute may be None: "-")."""
    head = ("| rate [Hz] | step | samples | misses | latency min / p50 / p99 / p99.9 / max [us] "
            "| compute p50 / p99 / max [us] | SCHED_FIFO | mlockall | CPU pinned |")
    lines = [head, "|---:|---|---:|---:|---|---|---|---|---|"]
    for r in rows:
        lat, comp = r["latency_us"], r["compute_us"]
        misses = "-" if r["misses"] is None else r["misses"]
        compute = "-" if comp is None else f"{comp['p50']:.1f} / {comp['p99']:.1f} / {comp['max']:.1f}"
        lines.append(
            f"| {r['rate_hz']:g} | {r['step']} | {r['samples']} | {misses} "
            f"| {lat['min']:.1f} / {lat['p50']:.1f} / {lat['p99']:.1f} / {lat['p99.9']:.1f} / {lat['max']:.1f} "
            f"| {compute} | {_yes(r, 'fifo')} | {_yes(r, 'mlockall')} | {_yes(r, 'cpu_affinity')} |")
    return "\n".join(lines)


def _yes(r: dict, name: str) -> str:
    if r[name]:
        return "yes"
    reason = r[f"{name}_reason"]
    return "not asked" if reason == "not requested" else "refused"


def _run(args) -> int:
    r = measure(args.rate, args.seconds, fifo=args.fifo, cpu=args.cpu, mlock=args.mlock, plant=args.plant)
    lat, comp = r["latency_us"], r["compute_us"]
    print(f"# servohydraulics latency: {r['samples']} samples at {r['rate_hz']:g} Hz "
          f"(period {1e6 * r['period_s']:.3f} us), step: {r['step']}")
    print(f"T: 0 C: {r['samples']:8d} Min: {lat['min']:8.1f} Avg: {lat['mean']:8.1f} P50: {lat['p50']:8.1f} "
          f"P99: {lat['p99']:8.1f} P99.9: {lat['p99.9']:8.1f} Max: {lat['max']:8.1f} [us]  Misses: {r['misses']}")
    print(f"compute per step [us]: p50 {comp['p50']:.1f}  p99 {comp['p99']:.1f}  max {comp['max']:.1f}"
          + (f"  plant failures {r['plant_failures']}" if args.plant else ""))
    for name in ("fifo", "mlockall", "cpu_affinity"):
        print(f"{name}: {r[f'{name}_reason']}")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(r, f, indent=2)
            f.write("\n")
        print(f"wrote {args.json}")
    return 0


def register(sub) -> None:
    p = sub.add_parser("latency",
                       help="measure how well this machine paces a loop to the wall clock (cyclictest style)")
    p.add_argument("--rate", type=float, required=True, help="loop rate [Hz], e.g. 2000 or 4096")
    p.add_argument("--seconds", type=float, default=10.0, help="run length [s] (default 10)")
    p.add_argument("--fifo", type=int, default=None, metavar="PRIO",
                   help="ask for SCHED_FIFO at this priority (1..99); refused -> runs without, says why")
    p.add_argument("--cpu", type=int, default=None, metavar="N", help="pin the loop's thread to CPU N")
    p.add_argument("--mlock", action="store_true", help="mlockall(MCL_CURRENT | MCL_FUTURE)")
    p.add_argument("--plant", action="store_true",
                   help="step the paper's plant (Zhao 2003, displacement control) once per sample in the loop")
    p.add_argument("--json", default=None, help="also write the figures to this JSON file")
    p.set_defaults(func=_run)
