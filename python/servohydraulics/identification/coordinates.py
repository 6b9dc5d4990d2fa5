"""Which rig keys identification fits, and in which coordinates (the one
:class:`Coordinates` of the package: log, linear or reciprocal per key).

One table per concern, easy to edit when the core gains fields:

* ``LOOP_KEYS``: the actuator loop's keys fitted by default in each control mode.
* ``SPECIMEN_KEYS``: the specimen's keys per ``--specimen`` kind: ``linear``
  (the structure's k, c), ``bouc_wen`` (issue 12's ``bouc_wen_hysteresis``:
  bw_k, bw_beta, bw_gamma with bw_A = 1 and bw_n held, since z scales with A,
  plus the viscous c and the mass m the load cell carries) and ``mr_damper``
  (issue 12's Spencer element: at one constant current the current-dependent
  pairs alpha_a + alpha_b u ... cannot be separated, so the ``_a`` terms are
  fitted with the ``_b`` ones and the voltage at 0; mr_A and mr_n are held for
  the same scaling reason; k0 and x0 are held at 0: x0 only offsets the force,
  k0 is below what the records resolve).
* ``FORCE_KEYS``: keys that act on the measured force (fitted on the force
  channel in displacement control, the others on the displacement).
* ``SPECIMEN_EFFECT``: the ``[effects]`` switch that turns the specimen on, if
  the rig has one.
* ``SIGNED_KEYS``: keys that may be negative (fitted linearly, not in log space).

Every other numeric field of ``Rig`` may be named in ``fit=[...]`` too (the
delays included: ``command_delay``, ``measurement_delay_force``, ``loop_delay``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _core
from ..rig import Rig

LOOP_KEYS = {"displacement": ("G_p", "f_v", "zeta_v"), "force": ("G_p", "f_v", "zeta_v")}

SPECIMEN_KEYS = {
    "linear": ("k", "c"),
    "bouc_wen": ("bw_k", "bw_beta", "bw_gamma", "c", "m"),
    "mr_damper": ("mr_alpha_a", "mr_c0_a", "mr_c1_a", "mr_k1", "mr_beta", "mr_gamma", "m"),
}

#: keys that act on the measured force and hardly on the displacement: in displacement
#: control they are fitted on the force channel, the others on the displacement
FORCE_KEYS = frozenset({k for ks in SPECIMEN_KEYS.values() for k in ks} |
                       {"measurement_delay_force", "F_c", "bw_A", "bw_n", "mr_k0", "mr_x0", "mr_A", "mr_n",
                        "mr_alpha_b", "mr_c0_b", "mr_c1_b", "mr_alpha_c", "mr_bw_decay"})

#: the Spencer element's fields (the fitted ones and those held at one constant current)
MR_DAMPER_FIELDS = ("mr_alpha_a", "mr_alpha_b", "mr_c0_a", "mr_c0_b", "mr_c1_a", "mr_c1_b", "mr_k0", "mr_k1",
                    "mr_x0", "mr_A", "mr_beta", "mr_gamma", "mr_n", "mr_voltage", "mr_current", "mr_alpha_c",
                    "mr_bw_decay")

SPECIMEN_EFFECT = {"linear": None, "bouc_wen": "bouc_wen_hysteresis", "mr_damper": "mr_damper"}

#: plausible ranges [SI] that bound a fit (the start is clipped into them).  The
#: valve's: a fit may otherwise turn Eq (2) into a first-order lag (zeta_v -> 1e4,
#: f_v -> 1 MHz), equal in the data but too stiff for a fixed-step integrator.
RANGES = {"f_v": (1.0, 300.0), "zeta_v": (0.1, 2.0)}

#: log-space keys move at most a factor exp(30) ~ 1e13 from their start
Z_LOG_MAX = 30.0

#: (the thesis' MR-damper law's alpha curvature and Bouc-Wen decay: identification.law)
SIGNED_KEYS = frozenset({"x_contact", "mr_alpha_c", "mr_bw_decay"})


def _bounds() -> dict[str, str]:
    return {p["key"]: p.get("bound", "") for p in _core.RIG_PARAMETERS}


def units() -> dict[str, str]:
    """Rig key -> SI unit, from the core's parameter table (``sh.PARAMETERS``)."""
    return {p["key"]: p["unit"] for p in _core.RIG_PARAMETERS}


#: the kinds of coordinate a key can be fitted in
KINDS = ("log", "linear", "reciprocal")


def specimen_keys(specimen: str) -> tuple[str, ...]:
    """The specimen's fitted keys; ValueError if unknown."""
    if specimen not in SPECIMEN_KEYS:
        raise ValueError(f"invalid specimen = {specimen!r}: expected one of {sorted(SPECIMEN_KEYS)}")
    return SPECIMEN_KEYS[specimen]


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
    """Fitting coordinates z of parameters, one kind per key (``KINDS``):

    * ``"log"``: z = log(value / start), for a positive key that cannot be negative
      (relative steps, no sign change);
    * ``"linear"``: z = (value - start) / scale;
    * ``"reciprocal"``: z = 1 / value (a value <= 0 in z is an infinite value), for a
      parameter whose "absent" is infinite (a valve bandwidth, a supply pressure): absent
      is z = 0, inside the range.

    ``about(rig, keys)`` (``sh.identify``) puts z = 0 at the rig's values, log or linear;
    ``absolute(keys, reciprocal)`` (``sh.diagnose``) fits the values themselves or their
    reciprocals."""

    keys: tuple[str, ...]
    start: np.ndarray
    kind: tuple[str, ...]
    scale: np.ndarray

    def __post_init__(self) -> None:
        bad = [k for k in self.kind if k not in KINDS]
        if bad or len(self.kind) != len(self.keys):
            raise ValueError(f"invalid coordinate kinds = {self.kind}: one of {KINDS} per key {self.keys}")

    @classmethod
    def about(cls, rig: Rig, keys, scales: dict | None = None) -> Coordinates:
        """z = 0 at the rig's values; a linear key's step scale is its start's size, or
        ``scales[key]`` (a key that may start at 0: law.coordinate_scales)."""
        start = np.array([float(np.clip(getattr(rig, k), *RANGES.get(k, (-np.inf, np.inf)))) for k in keys])
        kind = tuple("log" if s > 0 and k not in SIGNED_KEYS else "linear" for k, s in zip(keys, start))
        scale = np.array([float((scales or {}).get(k, max(abs(s), 1e-12))) for k, s in zip(keys, start)])
        return cls(tuple(keys), start, kind, scale)

    @classmethod
    def absolute(cls, keys, reciprocal) -> Coordinates:
        """z = value, or z = 1 / value where ``reciprocal``."""
        n = len(keys)
        return cls(tuple(keys), np.zeros(n), tuple("reciprocal" if r else "linear" for r in reciprocal), np.ones(n))

    @property
    def log(self) -> np.ndarray:
        return np.array([k == "log" for k in self.kind], dtype=bool)

    @property
    def reciprocal(self) -> np.ndarray:
        return np.array([k == "reciprocal" for k in self.kind], dtype=bool)

    def values(self, z: np.ndarray) -> np.ndarray:
        z = np.asarray(z, dtype=float)
        log, rec = self.log, self.reciprocal
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            out = np.where(log, self.start * np.exp(np.where(log, z, 0.0)), self.start + z * self.scale)
            return np.where(rec, np.where(z <= 0, np.inf, 1.0 / np.where(z <= 0, 1.0, z)), out)

    def z(self, values: np.ndarray) -> np.ndarray:
        v = np.asarray(values, dtype=float)
        log, rec = self.log, self.reciprocal
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            out = np.where(log, np.log(np.where(log, v / self.start, 1.0)), (v - self.start) / self.scale)
            return np.where(rec, np.where(np.isinf(v), 0.0, 1.0 / np.where(v == 0, np.inf, v)), out)

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
        """Interval of key i from z +- level_z sd (log and reciprocal keys: asymmetric in the value;
        an infinite sd: the key's whole range)."""
        a, b = self.values_at(i, z - level_z * sd), self.values_at(i, z + level_z * sd)
        return (min(a, b), max(a, b))

    def value_sd(self, i: int, z: float, sd: float) -> float:
        """Standard error of key i in its unit from sd in z (linearised)."""
        v = self.values_at(i, z)
        return float(sd * {"log": abs(v), "reciprocal": v * v, "linear": self.scale[i]}[self.kind[i]])

    def values_at(self, i: int, z: float) -> float:
        if not math.isfinite(z) and self.kind[i] != "reciprocal":  # an infinite sd: the end of the range
            return (0.0 if z < 0 else math.inf) if self.kind[i] == "log" else math.copysign(math.inf, z)
        if self.kind[i] == "log":
            return float(self.start[i]) * math.exp(min(max(z, -745.0), 709.0))  # a huge sd: 0 or inf
        if self.kind[i] == "reciprocal":
            return math.inf if z <= 0 else 1.0 / z
        return float(self.start[i] + z * self.scale[i])


__all__ = ["FORCE_KEYS", "KINDS", "LOOP_KEYS", "MR_DAMPER_FIELDS", "RANGES", "SIGNED_KEYS", "SPECIMEN_EFFECT",
           "SPECIMEN_KEYS", "Coordinates", "check_keys", "specimen_keys", "units", "use_specimen"]
