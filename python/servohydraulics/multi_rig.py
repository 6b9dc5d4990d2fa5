"""N servo-hydraulic actuators on one specimen (issue 23): the coupled multi-actuator rig.

Each actuator is the paper's model with its own rig (servo controller in displacement control,
Eq 2 servovalve, the nonlinear valve flow, compressibility, leakage, piston friction, drive
saturation); all act through rigid arms (the fixture) on one frame node (x, theta) that carries
a linear specimen.  The equations are the C++ core's (``_core.MultiRig``, multi_rig.hpp); this
module builds them from rigs or files and runs them on command records::

    import servohydraulics as sh
    rig = sh.load_multi_rig("marths_2act.toml")        # or sh.MultiActuatorRig(rigs, arms, angles, specimen)
    rig = sh.marths_rig()                              # the two-actuator rig calibrated to the maRTHS plant
    res = sh.simulate_multi(rig, u, dt=1 / 1024)       # u: (n, N) commands [m]
    res["actuator1.force"], res["node.theta"], res.units, res.warnings()
    plant = rig.make_plant(dt=1 / 1024)                # a _core.MultiRigPlant: reset(), displacements(), step(u)

Units are SI (m, rad, N, Pa).  docs/multi-actuator.md has the model, the channels and the calibration.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from .atomic import FileSet
from .response import Response, finish, limit_warnings, solver_warnings
from .rig import Rig, copy_rig, load_rig, rig_from_dict, rig_to_dict, zhao2003
from .simulate import _check_dt, solver_options

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

import tomli_w

#: The channels of one actuator (name -> unit), named ``actuator<i>.<name>`` in a run (i from 1).
ACTUATOR_CHANNELS = dict(map(tuple, _core.ACTUATOR_CHANNELS))
#: The node's channels (name -> unit), named ``node.<name>`` in a run.
NODE_CHANNELS = dict(map(tuple, _core.NODE_CHANNELS))

#: The maRTHS benchmark's coupler (BENCHMARK.md section 6): arm length [m] and angles [rad].
MARTHS_ARM = math.hypot(0.2667, 0.127)
MARTHS_ANGLES = (-math.radians(25.4633), math.radians(25.4633))

#: The frames a rig file or MultiActuatorRig names: name -> marths_frame's reduction.
FRAMES = {"marths": "guyan", "marths_static": "static"}

#: The committed rig files (the calibrated two-actuator maRTHS rig, docs/multi-actuator.md).
RIG_FILES = Path(__file__).parent / "rig_files"


def marths_frame(reduction: str = "guyan") -> dict[str, np.ndarray]:
    """The maRTHS benchmark's physical frame (BENCHMARK.md section 6, physicalFrame_feedbackForce.m)
    condensed to the interface node's (x [m], theta [rad]).

    The 5-DOF frame (X1, theta1..theta4; columns 0.7 x 2.520 in^4, axial terms removed, pinned base,
    ``M5 = 1.1 diag(M1x, M12z, M12z, M34z, M34z)``, 5 % modal damping with the frequencies rounded
    to 0.01 rad/s) is reduced with ``T = [I; G]``, ``G = -Koo^-1 Kot``:

    ``reduction="guyan"`` (default): ``T^T K5 T``, ``T^T M5 T``, ``T^T C5 T``, the consistent (energy
    preserving) reduction of the section's frame: its stiffness is the benchmark's condensed one and
    the slave rotations' inertia and damping follow the node.
    ``reduction="static"``: the scripts' own simplified 2-DOF model (``K_phys_2dof``: the same
    stiffness; ``M_phys_2dof = diag(M1x, M12z)`` without the factor 1.1; its own 5 % modal damping).

    Returns ``{"M", "C", "K"}`` (2 x 2 each; [[kg, kg m], [kg m, kg m^2]], ... ).
    """
    if reduction not in ("guyan", "static"):
        raise ValueError(f"invalid reduction = {reduction!r}: expected 'guyan' or 'static'")
    R = _core.marths
    kind = R.FrameReduction.Guyan if reduction == "guyan" else R.FrameReduction.Static
    fr = R.CondensedFrame.from_parameters(R.PhysicalFrameParameters(), kind)  # the one home: marths/structure.cpp
    return {"M": np.array(fr.M), "C": np.array(fr.C), "K": np.array(fr.K)}


def _matrix(name: str, value: Any, rotation: bool) -> list[float]:
    """A 2 x 2 (or, with theta locked, a scalar or 1 x 1) as the core's row-major list of 4."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"invalid specimen.{name} = {value!r}: expected numbers") from None
    if not rotation and a.size == 1:
        return [float(a.ravel()[0]), 0.0, 0.0, 0.0]
    if a.shape != (2, 2):
        raise ValueError(f"invalid specimen.{name} shape = {a.shape}: expected 2 x 2 in (x, theta)"
                         + ("" if rotation else " or a scalar (theta locked)"))
    return [float(v) for v in a.ravel()]


def node_specimen(M: ArrayLike, C: ArrayLike | None = None, K: ArrayLike | None = None, *, rotation: bool = True,
                  fixture_mass: float = 0.0, fixture_inertia: float = 0.0) -> _core.NodeSpecimen:
    """The specimen at the node: mass ``M``, damping ``C``, stiffness ``K`` in (x [m], theta [rad]),
    2 x 2 each ([[kg, kg m], [kg m, kg m^2]], [[N s/m, N s], [N s, N m s]], [[N/m, N], [N, N m]]), or
    scalars with ``rotation=False`` (theta locked at 0: the node translates only); the fixture's mass
    [kg] and rotary inertia about the node [kg m^2] move with it.  Validated (ValueError naming the
    entry and its value)."""
    sp = _core.NodeSpecimen()
    sp.rotation = bool(rotation)
    zero = np.zeros((2, 2)) if rotation else 0.0
    sp.M = _matrix("M", M, rotation)
    sp.C = _matrix("C", zero if C is None else C, rotation)
    sp.K = _matrix("K", zero if K is None else K, rotation)
    sp.fixture_mass = float(fixture_mass)
    sp.fixture_inertia = float(fixture_inertia)
    sp.validate()
    return sp


class MultiActuatorRig:
    """N actuators (one :class:`Rig` each) on rigid arms to one frame node with a specimen.

    Args:
        rigs: actuator i's rig (displacement control; its structure ``m, c, k`` is not used: the
            specimen is the node's; its friction acts on its piston).
        arms: arm lengths d_i [m] from the node to actuator i's attachment.
        angles: arm angles alpha_i [rad] from the actuator axis (stroke
            ``s_i = x + d_i (cos(theta + alpha_i) - cos(alpha_i))``).
        specimen: a :func:`node_specimen`, a dict with ``M``, ``C``, ``K`` (as :func:`marths_frame` returns),
            or a frame's name: ``"marths"`` (``marths_frame()``) or ``"marths_static"``
            (``marths_frame("static")``), which a rig file keeps by name.

    ``core`` is the validated ``_core.MultiRig``; construction raises ValueError naming a bad field
    (``actuators[1].K_v``, ``specimen.K[0][1]``, ...).
    """

    def __init__(self, rigs: Sequence[Rig], arms: Sequence[float], angles: Sequence[float],
                 specimen: _core.NodeSpecimen | dict[str, ArrayLike] | str):
        self.frame = None
        if isinstance(specimen, str):
            if specimen not in FRAMES:
                raise ValueError(f"invalid specimen = {specimen!r}: expected a frame name {list(FRAMES)}, a "
                                 "NodeSpecimen or a dict of M, C, K")
            self.frame, specimen = specimen, marths_frame(FRAMES[specimen])
        if isinstance(specimen, dict):
            specimen = node_specimen(**specimen)
        self.rigs = [r for r in rigs]
        self.arms = [float(d) for d in arms]
        self.angles = [float(a) for a in angles]
        self.specimen = specimen
        self.core = _core.MultiRig(self.rigs, self.arms, self.angles, specimen)

    @property
    def actuators(self) -> int:
        """N."""
        return self.core.actuators

    def __repr__(self) -> str:
        return (f"MultiActuatorRig(actuators={self.actuators}, arms={self.arms}, angles={self.angles}, "
                f"rotation={self.specimen.rotation}, states={self.core.num_states})")

    def specimen_matrix(self, name: str) -> np.ndarray:
        """The specimen's ``"M"``, ``"C"`` or ``"K"`` as a 2 x 2 array (the fixture's mass not included)."""
        if name not in ("M", "C", "K"):
            raise ValueError(f"invalid name = {name!r}: expected 'M', 'C' or 'K'")
        return np.reshape(getattr(self.specimen, name), (2, 2))

    def make_plant(self, dt: float, options: _core.SolverOptions | None = None) -> _core.MultiRigPlant:
        """The rig stepped at the loop's sample time ``dt`` [s] (a ``MultiActuatorSystem``: ``reset()``,
        ``displacements()`` [m], ``step(u)`` with the N commands [m], ``observe()``); ``options`` from
        :func:`servohydraulics.solver_options` (dopri5, cvode or rk4; default dopri5 at rtol 1e-8)."""
        return _core.MultiRigPlant(self.core, _check_dt(dt), options or solver_options())

    def linearize(self, u0: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C) about the rest state with the commands ``u0`` [m] (default 0): dy/dt = A dy + B du,
        strokes = C dy (the analytic Jacobian)."""
        u = np.zeros(self.actuators) if u0 is None else np.asarray(u0, dtype=float)
        return self.core.linearize(self.core.rest(), u)

    def frequency_response(self, frequencies: ArrayLike, u0: ArrayLike | None = None,
                           friction: bool = False) -> np.ndarray:
        """The linearised rig's command -> stroke frequency response at ``frequencies`` [Hz]:
        complex array (n_f, N, N), entry [k, i, j] from command j to stroke i [m/m].  The pistons'
        friction is left out unless ``friction``: linearised at rest it is the regularisation's slope
        F_c / v_stick, a stiff damper that a sliding piston never feels.  States without dynamics here
        (a zero row and column of A and a zero row of B: the bristle without LuGre, the spool without
        valve dynamics) are dropped, so that 0 Hz is defined."""
        rig = self
        if not friction and any(r.effects.coulomb_friction for r in self.rigs):
            rigs = [copy_rig(r) for r in self.rigs]
            for r in rigs:
                r.effects.coulomb_friction = False
            rig = MultiActuatorRig(rigs, self.arms, self.angles, self.specimen)
        A, B, C = rig.linearize(u0)
        keep = np.any(A != 0, axis=1) | np.any(A != 0, axis=0) | np.any(B != 0, axis=1)
        A, B, C = A[np.ix_(keep, keep)], B[keep], C[:, keep]
        f = np.atleast_1d(np.asarray(frequencies, dtype=float))
        eye = np.eye(A.shape[0])
        return np.stack([C @ np.linalg.solve(2j * np.pi * fk * eye - A, B) for fk in f])

    def to_dict(self, rig_files: Sequence[str] | None = None) -> dict[str, Any]:
        """The layout of a multi-actuator rig file (``rig_files``: the actuators' file names to refer to;
        else their parameters inline)."""
        sp = self.specimen
        matrices: dict[str, Any] = ({"frame": self.frame} if self.frame is not None else
                                    {k: self.specimen_matrix(k).tolist() for k in ("M", "C", "K")})
        out: dict[str, Any] = {
            "fixture": {"arms": list(self.arms), "angles": list(self.angles), "rotation": bool(sp.rotation)},
            "specimen": {**matrices, "fixture_mass": float(sp.fixture_mass),
                         "fixture_inertia": float(sp.fixture_inertia)},
        }
        out["actuators"] = ([{"rig": name} for name in rig_files] if rig_files is not None
                           else [rig_to_dict(r) for r in self.rigs])
        return out


def _read_toml(path: Path) -> dict[str, Any]:
    try:
        return tomllib.loads(path.read_bytes().decode("utf-8-sig"))
    except FileNotFoundError:
        raise FileNotFoundError(f"multi-actuator rig file not found: {path}") from None
    except UnicodeDecodeError as e:
        raise ValueError(f"multi-actuator rig file {path} is not UTF-8 text ({e.reason} at byte {e.start})") from None
    except (tomllib.TOMLDecodeError, ValueError, RecursionError) as e:
        raise ValueError(f"multi-actuator rig file {path} is not valid TOML: {e}") from None
    except IsADirectoryError:
        raise ValueError(f"multi-actuator rig file {path} is a directory") from None


_SECTIONS = ("fixture", "specimen", "actuators")
_FIXTURE_KEYS = ("arms", "angles", "angles_deg", "rotation")
_SPECIMEN_KEYS = ("frame", "M", "C", "K", "fixture_mass", "fixture_inertia")


def multi_rig_from_dict(data: dict[str, Any], folder: Path | None = None) -> MultiActuatorRig:
    """Builds a rig from a parsed multi-actuator rig file (the layout of :func:`load_multi_rig`);
    ``folder`` resolves the actuators' ``rig`` file names.  ValueError naming the key and the value."""
    for section in data:
        if section not in _SECTIONS:
            raise ValueError(f"unknown section [{section}]: expected one of {list(_SECTIONS)}")
    fixture = data.get("fixture", {})
    specimen = data.get("specimen", {})
    actuators = data.get("actuators")
    for name, table, keys in (("fixture", fixture, _FIXTURE_KEYS), ("specimen", specimen, _SPECIMEN_KEYS)):
        if not isinstance(table, dict):
            raise ValueError(f"invalid [{name}] = {table!r}: expected a table")
        for key in table:
            if key not in keys:
                raise ValueError(f"unknown key {name}.{key}: expected one of {list(keys)}")
    if not isinstance(actuators, list) or not actuators or not all(isinstance(a, dict) for a in actuators):
        raise ValueError("invalid [[actuators]]: expected one [[actuators]] table per actuator")
    if "arms" not in fixture:
        raise ValueError("missing fixture.arms: the arm length of each actuator [m]")
    if ("angles" in fixture) == ("angles_deg" in fixture):
        raise ValueError("give one of fixture.angles [rad] or fixture.angles_deg [deg]")
    arms = _numbers("fixture.arms", fixture["arms"])
    angles = (_numbers("fixture.angles", fixture["angles"]) if "angles" in fixture
              else [math.radians(a) for a in _numbers("fixture.angles_deg", fixture["angles_deg"])])
    rotation = fixture.get("rotation", True)
    if not isinstance(rotation, bool):
        raise ValueError(f"invalid fixture.rotation = {rotation!r}: expected true or false")
    frame = specimen.get("frame")
    if frame is not None:
        if frame not in FRAMES:
            raise ValueError(f"invalid specimen.frame = {frame!r}: expected one of {list(FRAMES)}")
        if any(k in specimen for k in ("M", "C", "K")):
            raise ValueError("give specimen.frame or specimen.M, C, K, not both")
        matrices = marths_frame(FRAMES[frame])
    else:
        if "M" not in specimen:
            raise ValueError("missing specimen.M (or specimen.frame)")
        matrices = {k: specimen[k] for k in ("M", "C", "K") if k in specimen}
    sp = node_specimen(**matrices, rotation=rotation,
                       fixture_mass=_number("specimen.fixture_mass", specimen.get("fixture_mass", 0.0)),
                       fixture_inertia=_number("specimen.fixture_inertia", specimen.get("fixture_inertia", 0.0)))
    rigs = []
    if len(actuators) != len(arms):
        raise ValueError(f"invalid [[actuators]] (count) = {len(actuators)}: one per arm of fixture.arms "
                         f"({len(arms)})")
    for i, table in enumerate(actuators):
        table = dict(table)
        base = zhao2003()
        name = table.pop("rig", None)
        if name is not None:
            if not isinstance(name, str):
                raise ValueError(f"invalid actuators[{i}].rig = {name!r}: expected a rig file name")
            path = Path(name) if folder is None else folder / name
            base = load_rig(path)
        try:
            rigs.append(rig_from_dict(table, base))
        except ValueError as e:  # the core's form, "invalid actuators[i].<key> = <value>: ..."
            msg = str(e)
            raise ValueError(f"invalid actuators[{i}].{msg[8:]}" if msg.startswith("invalid ")
                             else f"actuators[{i}]: {msg}") from None
    out = MultiActuatorRig(rigs, arms, angles, sp)
    out.frame = frame
    return out


def _number(where: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"invalid {where} = {value!r}: expected a finite number")
    return float(value)


def _numbers(where: str, value: Any) -> list[float]:
    if not isinstance(value, list):
        raise ValueError(f"invalid {where} = {value!r}: expected a list of numbers")
    return [_number(f"{where}[{i}]", v) for i, v in enumerate(value)]


def load_multi_rig(path: str | Path) -> MultiActuatorRig:
    """Reads a multi-actuator rig file (TOML)::

        [fixture]
        arms = [0.2954, 0.2954]              # m, one per actuator
        angles_deg = [-25.4633, 25.4633]     # or angles = [...] in rad
        rotation = true                      # false: theta locked (the node translates)

        [specimen]
        frame = "marths"                     # the benchmark's frame (marths_frame), or M, C, K:
        # M = [[7.7, 0.0], [0.0, 0.8]]       # [[kg, kg m], [kg m, kg m^2]]; C, K likewise
        fixture_mass = 0.0                   # kg
        fixture_inertia = 0.0                # kg m^2

        [[actuators]]
        rig = "actuator1.toml"               # a rig file, relative to this file (default: the preset)
        [actuators.controller]               # optional: any rig section, over that file
        G_p = 1.2

        [[actuators]]
        rig = "actuator2.toml"

    Bad input raises ValueError naming the file, the key and the value."""
    path = Path(path)
    data = _read_toml(path)
    try:
        return multi_rig_from_dict(data, path.parent)
    except (ValueError, FileNotFoundError) as e:
        raise type(e)(f"{path}: {e}") from None


def save_multi_rig(rig: MultiActuatorRig, path: str | Path, header: str = "") -> list[Path]:
    """Writes the rig file ``path`` and one rig file per actuator beside it (``<stem>_actuator<i>.toml``),
    all or none (``FileSet``).  Returns the paths written."""
    path = Path(path)
    names = [f"{path.stem}_actuator{i + 1}.toml" for i in range(rig.actuators)]
    head = "# servohydraulics multi-actuator rig file: SI units (docs/multi-actuator.md)\n" + header
    rig_head = "# servohydraulics rig file: SI units, keys after Zhao et al. (2003) Table I\n"
    with FileSet() as files:
        files.write_text(path, head + tomli_w.dumps(rig.to_dict(names)))
        for name, r in zip(names, rig.rigs):
            files.write_text(path.parent / name, rig_head + tomli_w.dumps(rig_to_dict(r)))
    return [path] + [path.parent / n for n in names]


def marths_rig() -> MultiActuatorRig:
    """The two-actuator rig on the maRTHS benchmark's coupler and physical frame, with each actuator's
    parameters fitted so that the linearised rig's command -> stroke frequency response is close to the
    benchmark's identified plant over 0-50 Hz (``studies/marths_rig_calibration.py``;
    docs/multi-actuator.md has the fit and where the physics departs from the identified plant)."""
    return load_multi_rig(RIG_FILES / "marths_2act.toml")


class MultiResponse(Response):
    """A multi-actuator run: every channel (``time``, ``node.*``, ``actuator<i>.*``, ``actuator<i>.command``,
    ``actuator<i>.flags``, per-row counts) with its unit, one row per loop sample (row k before command
    row k is applied).  ``warnings()`` names the actuator of each limit it hit."""

    def __init__(self, channels: dict[str, np.ndarray], *, rig: MultiActuatorRig, dt: float, work: Any = None):
        units = {"time": "s", "internal_steps": "-", "rhs_evals": "-"}
        units.update({f"node.{n}": u for n, u in NODE_CHANNELS.items()})
        for i in range(rig.actuators):
            units.update({f"actuator{i + 1}.{n}": u for n, u in ACTUATOR_CHANNELS.items()})
            units[f"actuator{i + 1}.command"] = "m"
            units[f"actuator{i + 1}.flags"] = "-"
        super().__init__(channels, kind="multi", mode="displacement", dt=dt, work=work, units=units)
        self.multi_rig = rig

    @property
    def actuators(self) -> int:
        """N."""
        return self.multi_rig.actuators

    def __getitem__(self, name: str) -> np.ndarray:
        """A channel by name (``res["actuator1.force"]``: the dotted names are not attributes)."""
        return self.channels[name]

    def _warning_list(self, rig: Rig | None) -> list[str]:
        out = []
        for i, r in enumerate(self.multi_rig.rigs):
            name = f"actuator{i + 1}"
            flags = self.channels[f"{name}.flags"]
            peak = float(np.max(np.abs(self.channels[f"{name}.force"]), initial=0.0))
            out += [f"{name}: {w}" for w in limit_warnings(flags, self.time, peak, r)]
        out += solver_warnings(self.work)
        if not self.success:
            out.append(self.message)
        return out

    def to_csv(self, path: str | Path) -> Path:
        """Every channel to a CSV file (``time`` first), whole or not at all."""
        from .atomic import atomic_path

        path = Path(path)
        names = list(self.channels)
        with atomic_path(path) as tmp:
            np.savetxt(tmp, np.column_stack([np.asarray(self.channels[n], dtype=float) for n in names]),
                       delimiter=",", header=",".join(names), comments="", fmt="%.10g")
        return path


def _commands(commands: ArrayLike, n_act: int) -> np.ndarray:
    try:
        u = np.asarray(commands, dtype=float)
    except (TypeError, ValueError):
        raise ValueError("invalid commands: not an array of numbers [m]") from None
    if u.ndim == 1 and n_act == 1:
        u = u[:, None]
    if u.ndim != 2 or u.shape[1] != n_act:
        raise ValueError(f"invalid commands shape = {u.shape}: expected (n, {n_act}), one column per actuator [m]")
    if u.shape[0] < 2:
        raise ValueError(f"invalid commands length = {u.shape[0]}: need at least 2 samples")
    bad = np.argwhere(~np.isfinite(u))
    if bad.size:
        k, i = bad[0]
        raise ValueError(f"invalid commands[{k}, {i}] = {u[k, i]}: commands must be finite [m]")
    return np.ascontiguousarray(u)


def simulate_multi(rig: MultiActuatorRig, commands: ArrayLike, dt: float,
                   options: _core.SolverOptions | None = None, raise_on_failure: bool = True) -> MultiResponse:
    """Runs the coupled rig from rest on ``commands`` (n, N) [m], one row per loop sample of ``dt`` [s]
    (held over the sample; row k of the result is measured before command row k is applied, the last
    row is held but not seen).  ``options``: :func:`servohydraulics.solver_options` (dopri5 default,
    cvode, rk4).  A failed run raises :class:`SimulationError` with the partial response (or returns
    it with ``raise_on_failure=False``)."""
    u = _commands(commands, rig.actuators)
    plant = rig.make_plant(dt, options)
    plant.reset()
    cols, summary = _core.run_multi_record(plant, u)
    rows = summary.rows
    data = {name: np.asarray(v)[:rows] for name, v in cols.items()}
    for i in range(rig.actuators):
        data[f"actuator{i + 1}.command"] = u[:rows, i].copy()
    return finish(MultiResponse(data, rig=rig, dt=plant.dt, work=summary), raise_on_failure)


__all__ = ["ACTUATOR_CHANNELS", "NODE_CHANNELS", "MultiActuatorRig", "MultiResponse", "load_multi_rig",
           "marths_frame", "marths_rig", "multi_rig_from_dict", "node_specimen", "save_multi_rig", "simulate_multi"]
