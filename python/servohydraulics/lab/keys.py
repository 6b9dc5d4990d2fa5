"""Which rig keys identification fits, and in which coordinates.

One table per concern, easy to edit when the core gains fields:

* ``LOOP_KEYS``: the actuator loop's keys fitted by default in each control mode.
* ``SPECIMEN_KEYS``: the specimen's keys per ``--specimen`` kind.  ``linear``
  is today's structure (stiffness k, damping c).  ``bouc_wen`` and
  ``mr_damper`` name the fields the specimen elements of issue 12 are expected
  to add to ``Rig`` (Spencer et al. 1997's modified Bouc-Wen with the paper's
  symbols, prefixed ``mr_`` because ``A`` is the piston area; a plain
  Bouc-Wen hysteresis prefixed ``bw_``).  Until ``Rig`` has them, asking for
  those specimens is a clear error (:func:`specimen_keys`).  For the MR damper
  at one constant current the current-dependent pairs (alpha_a + alpha_b u ...)
  cannot be separated, so the ``_a`` terms are fitted; ``mr_A`` and ``mr_n``
  are held (z is scaled by A: only alpha A is identifiable with beta, gamma).
* ``SPECIMEN_EFFECT``: the ``[effects]`` switch that turns the specimen on, if
  the rig has one.
* ``SIGNED_KEYS``: keys that may be negative (fitted linearly, not in log space).

Every other numeric field of ``Rig`` may be named in ``fit=[...]`` too (delays
of issue 12 included, e.g. ``command_delay``, ``loop_delay``, once they exist).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _core
from ..rig import Rig

LOOP_KEYS = {"displacement": ("G_p", "f_v", "zeta_v"), "force": ("G_p", "f_v", "zeta_v")}

SPECIMEN_KEYS = {
    "linear": ("k", "c", "m"),
    "bouc_wen": ("bw_k", "bw_beta", "bw_gamma", "c", "m"),
    "mr_damper": ("mr_alpha_a", "mr_c0_a", "mr_c1_a", "mr_k1", "mr_beta", "mr_gamma", "m"),
}

#: keys that act on the measured force and hardly on the displacement: in displacement
#: control they are fitted on the force channel, the others on the displacement
FORCE_KEYS = frozenset({k for ks in SPECIMEN_KEYS.values() for k in ks} |
                       {"measurement_delay_force", "F_c", "bw_A", "bw_n", "mr_k0", "mr_x0", "mr_A", "mr_n"})

#: the Spencer element's fields (the fitted ones and those held at one constant current)
MR_DAMPER_FIELDS = ("mr_alpha_a", "mr_alpha_b", "mr_c0_a", "mr_c0_b", "mr_c1_a", "mr_c1_b", "mr_k0", "mr_k1",
                    "mr_x0", "mr_A", "mr_beta", "mr_gamma", "mr_n", "mr_voltage")

SPECIMEN_EFFECT = {"linear": None, "bouc_wen": "bouc_wen_hysteresis", "mr_damper": "mr_damper"}

#: plausible ranges [SI] that bound a fit (the start is clipped into them).  The
#: valve's: a fit may otherwise turn Eq (2) into a first-order lag (zeta_v -> 1e4,
#: f_v -> 1 MHz), equal in the data but too stiff for a fixed-step integrator.
RANGES = {"f_v": (1.0, 300.0), "zeta_v": (0.1, 2.0)}

#: log-space keys move at most a factor exp(30) ~ 1e13 from their start
Z_LOG_MAX = 30.0

SIGNED_KEYS = frozenset({"x_contact"})


def _bounds() -> dict[str, str]:
    return {p["key"]: p.get("bound", "") for p in _core.RIG_PARAMETERS}


def specimen_keys(specimen: str) -> tuple[str, ...]:
    """The specimen's fitted keys; ValueError if unknown or if ``Rig`` lacks its fields."""
    if specimen not in SPECIMEN_KEYS:
        raise ValueError(f"invalid specimen = {specimen!r}: expected one of {sorted(SPECIMEN_KEYS)}")
    keys = SPECIMEN_KEYS[specimen]
    missing = [k for k in keys if not hasattr(Rig, k)]
    if missing:
        raise ValueError(f"specimen = {specimen!r} is not available yet: needs the specimen elements of issue 12 "
                         f"(Rig has no field(s) {missing})")
    return keys


def use_specimen(rig: Rig, specimen: str) -> None:
    """Switches the specimen's element on in ``rig`` (when the rig has such a switch)."""
    name = SPECIMEN_EFFECT[specimen]
    if name is not None and hasattr(rig.effects, name):
        setattr(rig.effects, name, True)


def check_keys(rig: Rig, keys) -> tuple[str, ...]:
    """The fit keys, validated: numeric fields of the rig, no repeats."""
    keys = tuple(keys)
    if not keys:
        raise ValueError("invalid fit = []: name at least one rig key to fit")
    for k in keys:
        v = getattr(rig, k, None) if isinstance(k, str) and not k.startswith("_") else None
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ValueError(f"invalid fit key = {k!r}: not a numeric rig field; e.g. {sorted(_bounds())}")
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise ValueError(f"invalid fit = {list(keys)}: key(s) {twice} given twice")
    return keys


@dataclass(frozen=True)
class Coordinates:
    """Fitting coordinates z of the keys about a start: z = log(value / start) for a
    positive start of a key that cannot be negative (relative steps, no sign change),
    else z = (value - start) / scale with scale = max(|start|, 1e-12).  z = 0 is the start."""

    keys: tuple[str, ...]
    start: np.ndarray
    log: np.ndarray
    scale: np.ndarray

    @classmethod
    def about(cls, rig: Rig, keys) -> Coordinates:
        start = np.array([float(np.clip(getattr(rig, k), *RANGES.get(k, (-np.inf, np.inf)))) for k in keys])
        log = np.array([s > 0 and k not in SIGNED_KEYS for k, s in zip(keys, start)])
        return cls(tuple(keys), start, log, np.maximum(np.abs(start), 1e-12))

    def values(self, z: np.ndarray) -> np.ndarray:
        return np.where(self.log, self.start * np.exp(np.where(self.log, z, 0.0)), self.start + z * self.scale)

    def z(self, values: np.ndarray) -> np.ndarray:
        v = np.asarray(values, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.log, np.log(np.where(self.log, v / self.start, 1.0)), (v - self.start) / self.scale)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Linear keys bounded below by 0 where the core's table says >= 0 or > 0."""
        b = _bounds()
        lo = np.array([-np.inf if (g or ">" not in b.get(k, "")) else -s / sc
                       for k, g, s, sc in zip(self.keys, self.log, self.start, self.scale)])
        lo = np.where(self.log, -Z_LOG_MAX, lo)
        hi = np.where(self.log, Z_LOG_MAX, np.inf)
        for i, k in enumerate(self.keys):
            if k in RANGES:
                lo[i], hi[i] = self.z(np.full(len(self.keys), RANGES[k][0]))[i], \
                    self.z(np.full(len(self.keys), RANGES[k][1]))[i]
        return lo, hi

    def apply(self, rig: Rig, z: np.ndarray) -> Rig:
        """A copy of ``rig`` with the keys at z."""
        import copy

        r = copy.copy(rig)
        for k, v in zip(self.keys, self.values(z)):
            setattr(r, k, float(v))
        return r

    def interval(self, z: float, sd: float, i: int, level_z: float) -> tuple[float, float]:
        """Interval of key i from z +- level_z sd (log keys: asymmetric in the value)."""
        a, b = self.values_at(i, z - level_z * sd), self.values_at(i, z + level_z * sd)
        return (min(a, b), max(a, b))

    def values_at(self, i: int, z: float) -> float:
        if self.log[i]:
            return float(self.start[i] * math.exp(z))
        return float(self.start[i] + z * self.scale[i])


__all__ = ["FORCE_KEYS", "LOOP_KEYS", "RANGES", "MR_DAMPER_FIELDS", "SIGNED_KEYS", "SPECIMEN_EFFECT", "SPECIMEN_KEYS", "Coordinates",
           "check_keys", "specimen_keys", "use_specimen"]
