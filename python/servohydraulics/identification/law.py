"""An MR damper's field law identified across records at different currents or voltages.

A lab tests a damper at a few constant coil currents (or drive voltages) and needs it at
any other.  ``sh.identify([rec_0A, rec_1A], currents=[0, 1], specimen="mr_damper")``
fits one rig to all the records: one actuator loop (every loop key common), the damper's
field-independent keys common, and the coefficients of the law of its field-dependent
parameters (the core's MR element, ``[specimen] mr_law``), each record simulated at its
own field value (``Response.settings``, ``run.record_rig``).  The laws:

* ``"spencer"`` (Spencer et al. 1997, the default): alpha = alpha_a + alpha_b u,
  c0 = c0_a + c0_b u, c1 = c1_a + c1_b u; beta, gamma constant;
* ``"quiroz2022"`` (the UTFSM thesis' law, ``baselines.thesis_mr_parameters``): alpha
  quadratic, alpha_a + alpha_b u + alpha_c u^2, c0 and c1 linear, beta and gamma both
  scaled by exp(-mr_bw_decay u) (the thesis has beta = gamma).

u is the field input the rig names (``[specimen] mr_input``): ``mr_current`` [A] or
``mr_voltage`` [V].  A law is determined only by as many distinct field values as it has
coefficients per parameter: with one field value the ``_a`` terms carry it (the slopes
held at 0, as for a single record); with two, the linear terms and the exponential decay;
alpha's curvature ``mr_alpha_c`` needs three (with fewer it is held at its start, 0 for a
generic start, and the result says so).  The identified rig records the range of field
values it was fitted on (``mr_law_min``, ``mr_law_max``): a run outside it is reported
as an extrapolation (``Response.warnings``).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..response import Response
from ..rig import CHOICES, Rig, choice_name

#: the field input's kind -> (the rig key of its value, its unit)
FIELD_INPUTS = {"current": ("mr_current", "A"), "voltage": ("mr_voltage", "V")}
#: ``[specimen] mr_input`` name -> the core's enum
MR_INPUTS = CHOICES["mr_input"][1]
#: ``[specimen] mr_law`` name -> the core's enum
MR_LAWS = CHOICES["mr_law"][1]

#: the field-dependent parameters' law coefficients: (constant, slope) per parameter
LINEAR_TERMS = (("mr_alpha_a", "mr_alpha_b"), ("mr_c0_a", "mr_c0_b"), ("mr_c1_a", "mr_c1_b"))
#: the keys that do not depend on the field (shared by every record)
FIELD_FREE_KEYS = ("mr_k1", "mr_beta", "mr_gamma", "m")
#: the extra coefficients of the thesis' law, and how many distinct field values each needs
QUIROZ_TERMS = {"mr_bw_decay": 2, "mr_alpha_c": 3}


@dataclass(frozen=True)
class FieldInput:
    """The field each record was made at: ``kind`` ("current" or "voltage") and one value per
    record [A or V], in the records' order."""

    kind: str
    values: tuple[float, ...]

    @property
    def key(self) -> str:
        return FIELD_INPUTS[self.kind][0]

    @property
    def unit(self) -> str:
        return FIELD_INPUTS[self.kind][1]

    @property
    def levels(self) -> int:
        """How many distinct field values the records hold."""
        return len(set(self.values))

    def to_dict(self) -> dict:
        return {"input": self.kind, "unit": self.unit, "values": list(self.values),
                "range": [min(self.values), max(self.values)]}


def field_value(value, where: str) -> float:
    """A field value [A or V]: a finite number >= 0, else a ValueError naming ``where`` and the value."""
    raw = value
    if isinstance(value, str):
        try:
            value = float(value.strip())
        except ValueError:
            raise ValueError(f"invalid {where} = {raw!r}: expected a number") from None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"invalid {where} = {raw!r}: expected a number")
    v = float(value)
    if not math.isfinite(v) or v < 0.0:
        raise ValueError(f"invalid {where} = {raw!r}: must be finite and >= 0")
    return v


def parse_values(text: str, flag: str) -> list[float]:
    """The comma-separated values of a command-line flag (``--current 0,0.5,1``)."""
    items = [t.strip() for t in str(text).split(",")]
    if not text or any(not t for t in items):
        raise ValueError(f"invalid {flag} = {text!r}: expected comma-separated numbers, one per record")
    return [field_value(t, f"{flag} value {i + 1}") for i, t in enumerate(items)]


def field_input(records: Sequence[Response], currents=None, voltages=None) -> FieldInput | None:
    """The records' field input from ``currents`` [A] or ``voltages`` [V] (one per record, in
    order; None: not given).  ValueError naming the argument and the value: both given, a
    count that does not match the records, a value that is not a finite number >= 0."""
    if currents is not None and voltages is not None:
        raise ValueError("invalid field input: currents and voltages both given; an MR damper's law reads one "
                         "(give --current or --voltage, not both)")
    if currents is None and voltages is None:
        return None
    kind, values = ("current", currents) if currents is not None else ("voltage", voltages)
    if isinstance(values, (str, int, float)):
        values = [values]
    values = list(values)
    if len(values) != len(records):
        names = ", ".join(str(r.path.name) if r.path is not None else f"record {i + 1}"
                          for i, r in enumerate(records))
        raise ValueError(f"invalid {kind}s = {values!r}: {len(values)} value(s) for {len(records)} record(s) "
                         f"({names}); give one {kind} per record, in order")
    out = []
    for i, (v, r) in enumerate(zip(values, records)):
        where = f"{kind} of {r.path.name if r.path is not None else f'record {i + 1}'}"
        out.append(field_value(v, where))
    return FieldInput(kind, tuple(out))


def check_law(law: str) -> str:
    if law not in MR_LAWS:
        raise ValueError(f"invalid law = {law!r}: expected one of {sorted(MR_LAWS)}")
    return law


def law_keys(law: str, levels: int) -> tuple[tuple[str, ...], list[str]]:
    """(the damper's fitted keys, notes on the coefficients held) for ``law`` with ``levels``
    distinct field values (the loop's keys come on top)."""
    check_law(law)
    notes = []
    if levels < 2:
        keys = tuple(a for a, _ in LINEAR_TERMS)
        notes.append("one field value: the law's slopes (mr_alpha_b, mr_c0_b, mr_c1_b) are held at 0, its _a terms "
                     "carry the records' field; records at two or more field values identify the law")
    else:
        keys = tuple(k for pair in LINEAR_TERMS for k in pair)
    keys += FIELD_FREE_KEYS
    if law == "quiroz2022":
        for key, need in QUIROZ_TERMS.items():
            if levels >= need:
                keys += (key,)
            else:
                notes.append(f"{key} is held at its start: {levels} distinct field value(s), it needs {need}")
    return keys, notes


def set_field(rig: Rig, kind: str, value: float) -> Rig:
    """A copy of ``rig`` driven by the field ``kind`` ("current" or "voltage") at ``value`` (the
    other input at 0)."""
    key = FIELD_INPUTS[kind][0]
    out = copy.copy(rig)
    out.mr_input = MR_INPUTS[kind]
    for other, _ in FIELD_INPUTS.values():
        setattr(out, other, 0.0)
    setattr(out, key, float(value))
    return out


def rig_field(rig: Rig) -> tuple[str, float]:
    """(the rig's field input kind, its value)."""
    kind = choice_name(rig, "mr_input")
    return kind, float(getattr(rig, FIELD_INPUTS[kind][0]))


def predict_at(rig: Rig, current=None, voltage=None) -> Rig:
    """The rig at a field value for a prediction (``compare --current``): a copy with the value
    set; ValueError naming the flag when the rig has no MR damper, both are given, the value is
    not a finite number >= 0, or the rig's law reads the other input."""
    if current is None and voltage is None:
        return rig
    if current is not None and voltage is not None:
        raise ValueError("invalid field input: --current and --voltage both given; an MR damper's law reads one")
    kind, value = ("current", current) if current is not None else ("voltage", voltage)
    value = field_value(value, f"--{kind}")
    if not rig.effects.mr_damper:
        raise ValueError(f"invalid --{kind} = {value!r}: the rig has no MR damper (effects.mr_damper = false)")
    have = rig_field(rig)[0]
    if have != kind:
        raise ValueError(f"invalid --{kind} = {value!r}: the rig's MR damper law reads a {have} "
                         f"([specimen] mr_input = \"{have}\"); give --{have}")
    return set_field(rig, kind, value)


def law_start(rig: Rig, records: Sequence[Response], field: FieldInput, law: str) -> None:
    """The law's start in ``rig`` from the generic damper start of each record
    (``generic.mr_damper_start``: a Bingham fit per record): alpha, c0, c1 regressed on the field
    (least squares, linear; slopes floored at 1 % of the parameter's mean per unit of the largest
    field value, so that they start positive), the field-free keys averaged; ``mr_alpha_c`` and
    ``mr_bw_decay`` start at 0.  Sets the law, the field input and its identified range."""
    from .generic import mr_damper_start

    u = np.asarray(field.values, dtype=float)
    per = []
    for rec in records:
        r = copy.copy(rig)
        mr_damper_start(r, rec)
        per.append(r)
    mr_damper_start(rig, records[0])  # A, n, k0, x0, the structure's k, c
    u_max = max(float(u.max()), 1e-12)
    for a, b in LINEAR_TERMS:
        y = np.array([getattr(r, a) for r in per])
        if field.levels >= 2:
            slope, const = np.polyfit(u, y, 1)
            slope = max(float(slope), 0.01 * float(np.mean(y)) / u_max)
            const = max(float(np.mean(y - slope * u)), 0.01 * float(np.mean(y)))
        else:
            slope, const = 0.0, float(np.mean(y))
        setattr(rig, a, const)
        setattr(rig, b, slope)
    for k in FIELD_FREE_KEYS:
        setattr(rig, k, float(np.mean([getattr(r, k) for r in per])))
    rig.mr_law = MR_LAWS[check_law(law)]
    rig.mr_alpha_c = 0.0
    rig.mr_bw_decay = 0.0
    start_range(rig, field)


def start_range(rig: Rig, field: FieldInput) -> None:
    """The rig's field input (kind, the first record's value) and the range it is identified on."""
    rig.mr_input = MR_INPUTS[field.kind]
    for other, _ in FIELD_INPUTS.values():
        setattr(rig, other, 0.0)
    setattr(rig, field.key, field.values[0])
    rig.mr_law_min, rig.mr_law_max = min(field.values), max(field.values)


def coordinate_scales(rig: Rig, field: FieldInput) -> dict[str, float]:
    """Scales in the fitting coordinates of the law's coefficients that may start at 0 (a start
    rig identified at one field value has no slopes; the thesis law's terms start at 0): a slope
    by its constant term per unit of the largest field value, ``mr_alpha_c`` by alpha's size over
    that value squared, ``mr_bw_decay`` by 1 / that value."""
    u_max = max(max(field.values), 1e-12)
    out = {b: max(getattr(rig, a), 1e-12) / u_max for a, b in LINEAR_TERMS}  # a slope that starts at 0
    out.update({"mr_alpha_c": max(abs(rig.mr_alpha_a) + abs(rig.mr_alpha_b) * u_max, 1.0) / u_max**2,
                "mr_bw_decay": 1.0 / u_max})
    return out


def with_fields(records: Sequence[Response], field: FieldInput) -> list[Response]:
    """The records, each carrying its field value (``Response.settings``)."""
    return [r.with_settings(**{field.key: v}) for r, v in zip(records, field.values)]


__all__ = ["FIELD_FREE_KEYS", "FIELD_INPUTS", "FieldInput", "LINEAR_TERMS", "MR_INPUTS", "MR_LAWS", "QUIROZ_TERMS",
           "check_law", "coordinate_scales", "field_input", "field_value", "law_keys", "law_start", "parse_values",
           "predict_at", "rig_field", "set_field", "start_range", "with_fields"]
