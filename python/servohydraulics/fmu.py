"""FMI 2.0 co-simulation FMUs of the plant and of the EFT and RPsD controllers.

``export_fmu(rig, "plant.fmu")`` writes a zip holding

* ``modelDescription.xml``: the FMU's variables, from the core's variable table
  (``_core.fmu_variables``, cpp/fmu/model.hpp), with their start values;
* ``binaries/linux64/<modelIdentifier>.so``: the one FMU binary, built by CMake
  with the package and shipped in it (``servohydraulics_fmu.so``), copied under
  the FMU's name: no compiler is needed to export;
* ``resources/rig.toml`` (the rig, as dotted keys; ``sh.load_rig`` reads it) and
  ``resources/fmu.toml`` (kind, mode, GUID and the other parameters), which the
  binary reads at ``fmi2Instantiate``.

The interface (inputs, outputs, parameters, timing) is in docs/fmu.md.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
import uuid
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from . import _core
from .loops import eft_config, rpsd_config
from .response import Response
from .rig import Rig, load_rig, rig_to_dict
from .simulate import MODES, check_x0
from .timegrid import positive

KINDS = _core.FMU_KINDS  #: ("plant", "eft", "rpsd"), the FMU model's table (cpp/fmu/model.hpp)
#: The binary CMake builds (cpp/fmu) and installs into the package.
BINARY = "servohydraulics_fmu.so"
#: Longest modelIdentifier: it names binaries/linux64/<name>.so (file names end at 255 bytes).
MAX_NAME = 200
#: The control mode each controller drives.
CONTROLLER_MODES = {"eft": "force", "rpsd": "displacement"}


def binary_path() -> Path:
    """The FMU binary shipped with the package (or in SERVOHYDRAULICS_CORE_DIR's build tree)."""
    from . import __path__ as package_path

    for d in package_path:
        p = Path(d) / BINARY
        if p.is_file():
            return p
    raise FileNotFoundError(f"the FMU binary {BINARY} is not in {list(package_path)}: build the package with "
                            "SH_BUILD_FMU=ON (the wheel does; scripts/dev-build.sh does)")


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, int):
        return str(v)
    return repr(float(v))  # shortest repr: the binary reads back the same double


def _start(var: dict):
    """The start value as the resources and the XML write it."""
    v = var["start"]
    if var["type"] == "Boolean":
        return bool(v)
    if var["type"] == "Integer":
        return int(v)
    if var["type"] == "Enumeration":
        if not 0 <= int(v) < len(var["items"]):  # a core enum value the FMU's item list lacks (cpp/fmu/model.cpp)
            raise ValueError(f"invalid {var['name']} = {int(v)}: the FMU knows only {var['items']}")
        return var["items"][int(v)]
    return float(v)


def _rig_lines(rig: Rig) -> list[str]:
    lines = []
    for section, table in rig_to_dict(rig).items():
        for key, value in table.items():
            if isinstance(value, dict):  # servovalve.flow_curve
                lines += [f"{section}.{key}.{k} = {_toml_value(v)}" for k, v in value.items()]
            else:
                lines.append(f"{section}.{key} = {_toml_value(value)}")
    return lines


def _fmu_lines(kind: str, mode: str, guid: str, variables: list[dict]) -> list[str]:
    lines = [f"kind = {_toml_value(kind)}", f"mode = {_toml_value(mode)}", f"guid = {_toml_value(guid)}"]
    lines += [f"{v['name']} = {_toml_value(_start(v))}" for v in variables
              if v["causality"] == "parameter" and not v["in_rig"]]
    return lines


def _xml_start(var: dict) -> str:
    v = _start(var)
    if var["type"] == "Boolean":
        return "true" if v else "false"
    if var["type"] == "Enumeration":
        return str(int(var["start"]))
    return str(v) if var["type"] == "Integer" else repr(v)


def _unit(var: dict) -> str:
    """The variable's unit for the XML ("" for dimensionless: the core's "-")."""
    return var["unit"] if var["type"] == "Real" and var["unit"] not in ("", "-") else ""


def _scalar_variable(parent: ET.Element, var: dict) -> None:
    attrs = {"name": var["name"], "valueReference": str(var["value_reference"]),
             "causality": var["causality"], "variability": var["variability"]}
    if var["description"]:
        attrs["description"] = var["description"]
    if var["causality"] == "parameter":
        attrs["initial"] = "exact"
    sv = ET.SubElement(parent, "ScalarVariable", attrs)
    typed = {}
    if var["type"] == "Enumeration":
        typed["declaredType"] = var["type_name"]
    if _unit(var):
        typed["unit"] = var["unit"]
    if var["causality"] != "output":
        typed["start"] = _xml_start(var)
    ET.SubElement(sv, var["type"], typed)


def _model_structure(root: ET.Element, kind: str, variables: list[dict]) -> None:
    index = {v["name"]: i + 1 for i, v in enumerate(variables)}  # 1-based ScalarVariable index
    inputs = " ".join(str(index[v["name"]]) for v in variables if v["causality"] == "input")
    # Plant outputs are the state at the communication point (no feedthrough);
    # a controller's outputs are computed from its inputs at that point.
    deps = "" if kind == "plant" else inputs
    ms = ET.SubElement(root, "ModelStructure")
    outs, init = ET.SubElement(ms, "Outputs"), ET.SubElement(ms, "InitialUnknowns")
    for v in variables:
        if v["causality"] == "output":
            ET.SubElement(outs, "Unknown", {"index": str(index[v["name"]]), "dependencies": deps})
            ET.SubElement(init, "Unknown", {"index": str(index[v["name"]])})


def model_description(kind: str, mode: str, name: str, guid: str, dt: float, variables: list[dict]) -> bytes:
    """modelDescription.xml of an FMU (FMI 2.0, co-simulation)."""
    from . import __version__

    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": name, "guid": guid,
        "description": f"servohydraulics {kind} ({mode} control), Zhao et al. (2003)",
        "generationTool": f"servohydraulics {__version__}", "variableNamingConvention": "flat",
        "numberOfEventIndicators": "0"})
    ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": name, "needsExecutionTool": "false", "canHandleVariableCommunicationStepSize": "true",
        "canInterpolateInputs": "false", "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "false", "canSerializeFMUstate": "false", "providesDirectionalDerivative": "false"})
    units = sorted({v["unit"] for v in variables if _unit(v)})
    if units:
        ud = ET.SubElement(root, "UnitDefinitions")
        for u in units:
            ET.SubElement(ud, "Unit", {"name": u})
    enums = {v["type_name"]: v["items"] for v in variables if v["type"] == "Enumeration"}
    if enums:
        td = ET.SubElement(root, "TypeDefinitions")
        for tname, items in enums.items():
            e = ET.SubElement(ET.SubElement(td, "SimpleType", {"name": tname}), "Enumeration")
            for i, item in enumerate(items):
                ET.SubElement(e, "Item", {"name": item, "value": str(i)})
    ET.SubElement(ET.SubElement(root, "LogCategories"), "Category",
                  {"name": "logStatusError", "description": "errors: bad parameters, solver failures"})
    ET.SubElement(root, "DefaultExperiment", {"startTime": "0.0", "stepSize": repr(float(dt))})
    mv = ET.SubElement(root, "ModelVariables")
    for v in variables:
        _scalar_variable(mv, v)
    _model_structure(root, kind, variables)
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def settings(kind: str) -> list[str]:
    """The controller settings an FMU of ``kind`` takes (``export_fmu``'s ``**config``; none for the plant)."""
    import inspect

    if kind == "plant":
        return []
    maker = eft_config if kind == "eft" else rpsd_config
    # every field of the controller's config (cpp/fmu/model.cpp add_config) but dt, its own argument
    return [p for p in inspect.signature(maker).parameters if p != "dt"]


def _configs(kind: str, dt: float | None, config: dict):
    eft, rpsd = _core.EftConfig(), _core.RpsdConfig()
    unknown = sorted(set(config) - set(settings(kind)) - {"physical_mass_fraction"})
    if unknown and kind != "plant":
        raise ValueError(f"invalid setting {unknown[0]!r} for kind = {kind!r}: expected one of {settings(kind)}")
    if kind == "eft":
        eft = eft_config(dt, **config)
    elif kind == "rpsd":
        if "physical_mass_fraction" in config:
            raise ValueError("physical_mass_fraction is a setting of the simulated loop: export the physical rig "
                             "(RealTimePseudoDynamicTest.physical_rig) instead")
        rpsd = rpsd_config(dt, **config)
    elif config:
        raise ValueError(f"invalid keywords {sorted(config)} for kind = 'plant': the plant takes none")
    if dt is None:
        dt = (eft if kind == "eft" else rpsd).dt
    return float(dt), eft, rpsd


def _check(kind: str, mode: str | None, name: str | None) -> tuple[str, str]:
    if kind not in KINDS:
        raise ValueError(f"invalid kind = {kind!r}: expected one of {list(KINDS)}")
    if kind == "plant":
        mode = mode or "displacement"
        if mode not in MODES:
            raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    elif mode not in (None, CONTROLLER_MODES[kind]):
        raise ValueError(f"invalid mode = {mode!r} for kind = {kind!r}: the {kind} controller drives "
                         f"{CONTROLLER_MODES[kind]} control")
    name = f"servohydraulics_{kind}" if name is None else name
    if not isinstance(name, str) or not name.isidentifier() or not name.isascii():
        raise ValueError(f"invalid name = {name!r}: the modelIdentifier must be a C identifier")
    if len(name) > MAX_NAME:
        raise ValueError(f"invalid name = {name[:40]!r}... ({len(name)} characters): the modelIdentifier names "
                         f"the binary <name>.so, at most {MAX_NAME} characters")
    return mode or CONTROLLER_MODES[kind], name


def export_fmu(rig: Rig, path: str | os.PathLike, kind: str = "plant", mode: str | None = None,
               dt: float | None = None, x0: float = 0.0, solver_options: _core.SolverOptions | None = None,
               name: str | None = None, **config) -> Path:
    """Writes an FMI 2.0 co-simulation FMU (Linux x86_64) of the plant or a controller.

    Args:
        rig: the plant's rig (kind ``"plant"``), the EFT controller's model of the
            rig (``"eft"``), or the physical rig under test (``"rpsd"``).
        path: the ``.fmu`` file to write (replaced atomically).
        kind: ``"plant"``, ``"eft"`` or ``"rpsd"``.
        mode: the plant's control mode, ``"displacement"`` (command in m),
            ``"force"`` (N) or ``"free"`` (N); the controllers' modes are fixed
            (EFT: force, RPsD: displacement).
        dt: the controller sample [s] (None: the core's 0.5 ms; finite, >= 1e-7 s): every doStep is a
            whole number of samples, at most 10 million of them.
        x0: the plant's initial displacement [m] (static equilibrium there; within +-100 m as ``simulate``).
        solver_options: the plant's ODE integrator (``sh.solver_options(...)``).
        name: the FMU's modelIdentifier (default ``servohydraulics_<kind>``; a C identifier of at
            most ``MAX_NAME`` characters).
        **config: the controller's settings, as ``run_eft`` / ``run_rpsd`` take them:
            ``settings(kind)``, the keywords of the config table's fields that are FMU
            parameters (``_core.EFT_CONFIG_FIELDS`` / ``RPSD_CONFIG_FIELDS``, docs/fmu.md).

    Returns:
        The path written.  Raises ValueError naming a bad argument, FileNotFoundError
        when the package was built without the FMU binary.
    """
    mode, name = _check(kind, mode, name)
    x0 = check_x0(x0)  # as simulate checks it
    if dt is not None:
        dt = positive("dt", dt)  # and >= _core.FMU_MIN_DT: fmu_variables checks it (cpp/fmu/model.hpp)
    dt, eft, rpsd = _configs(kind, dt, config)
    solver = solver_options or _core.SolverOptions()
    variables = _core.fmu_variables(kind, mode, rig, dt, float(x0), solver, eft, rpsd)
    rig_toml = "\n".join(["# the rig (sh.load_rig reads this file)", *_rig_lines(rig)]) + "\n"
    digest = hashlib.sha256((kind + mode + name + rig_toml + repr(variables)).encode()).hexdigest()
    guid = "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, "servohydraulics-fmu:" + digest)) + "}"
    fmu_toml = "\n".join(["# the FMU's kind and parameters (read by its binary at fmi2Instantiate)",
                          *_fmu_lines(kind, mode, guid, variables)]) + "\n"
    files = {"modelDescription.xml": model_description(kind, mode, name, guid, dt, variables),
             "resources/rig.toml": rig_toml.encode(), "resources/fmu.toml": fmu_toml.encode()}
    return _write_zip(Path(path), files, binary_path(), f"binaries/linux64/{name}.so")


def _write_zip(path: Path, files: dict[str, bytes], binary: Path, arcname: str) -> Path:
    """The zip, through the package's atomic writer: replaced whole or not at all, with the
    umask's permissions like every other output."""
    from .atomic import atomic_path

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for arc, data in files.items():
            z.writestr(arc, data)
        info = zipfile.ZipInfo(arcname)
        info.external_attr = 0o755 << 16
        info.compress_type = zipfile.ZIP_DEFLATED
        z.writestr(info, binary.read_bytes())
    return path


class _Slave:
    """One FMU instance driven by variable name through fmpy (imported on first use)."""

    def __init__(self, path, workdir: str, instance: str):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.dir = extract(str(path), unzipdir=os.path.join(workdir, instance))
        self.md = read_model_description(self.dir)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.outputs = [v.name for v in self.md.modelVariables if v.causality == "output" and v.type == "Real"]
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.dt = float(self.md.defaultExperiment.stepSize)
        from .rig import tomllib  # the standard library's, or tomli before Python 3.11

        with open(os.path.join(self.dir, "resources", "fmu.toml"), "rb") as f:
            self.settings = tomllib.load(f)  # kind, mode, ... (written by export_fmu)

    def refs(self, names):
        return [self.vr[n] for n in names]

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def cosimulate(plant, controller, ground_acceleration, external_force=None, restoring_force_error=None,
               progress: bool = False) -> Response:
    """A plant FMU and a controller FMU in closed loop, through fmpy, at the controller rate.

    The co-simulation master of docs/fmu.md (Gauss-Seidel): at each t_k the plant's
    outputs go to the controller's ``sensors.*`` inputs with a_g(t_k) (and, for
    RPsD, P_ext and the restoring-force error); the controller's ``command`` at
    t_k goes to the plant; both step by dt.  Row k holds the plant's outputs at
    t_k and what the controller computed from them: the rows of ``sh.run_eft`` /
    ``sh.run_rpsd`` on the same inputs.  Needs fmpy.

    Returns:
        A :class:`~servohydraulics.response.Response` of ``kind`` ``"eft"`` or ``"rpsd"`` (the
        controller FMU's), its ``mode`` (force or displacement), ``dt`` and ``rig`` (the plant
        FMU's, read back from its resources): channels ``time``, the plant's outputs and the
        controller's outputs, with the units of the library's channel tables.  ValueError if
        ``controller`` is not a controller FMU or ``plant`` is not a plant FMU.
    """
    from tqdm import tqdm

    ag = np.asarray(ground_acceleration, dtype=float)
    extra = {"external_force": external_force, "restoring_force_error": restoring_force_error}
    extra = {k: np.broadcast_to(np.asarray(v, dtype=float), ag.shape) for k, v in extra.items() if v is not None}
    with tempfile.TemporaryDirectory(prefix="sh_cosim_") as work:
        p, c = _Slave(plant, work, "plant"), _Slave(controller, work, "controller")
        try:
            for slave, role, kinds in ((p, "plant", ("plant",)), (c, "controller", CONTROLLER_MODES)):
                if slave.settings.get("kind") not in kinds:
                    raise ValueError(f"invalid {role} = {str(plant if role == 'plant' else controller)!r}: an FMU of "
                                     f"kind {slave.settings.get('kind')!r}, expected {' or '.join(map(repr, kinds))}")
            kind = c.settings["kind"]
            rig = load_rig(os.path.join(p.dir, "resources", "rig.toml"))
            if not math.isclose(p.dt, c.dt, rel_tol=1e-12):
                raise ValueError(f"the plant's dt = {p.dt} s differs from the controller's dt = {c.dt} s")
            sensors = c.refs(f"sensors.{n}" for n in p.outputs)
            inputs = c.refs(["ground_acceleration", *extra])
            signals = np.column_stack([ag, *extra.values()])
            rows = np.empty((ag.size, len(p.outputs) + len(c.outputs)))
            p_out, c_out, u_ref = p.refs(p.outputs), c.refs(c.outputs), p.refs(["command"])
            i_cmd = c.outputs.index("command")
            for k in tqdm(range(ag.size), disable=not progress, desc="co-simulation"):
                y = p.fmu.getReal(p_out)
                c.fmu.setReal(sensors, y)
                c.fmu.setReal(inputs, list(signals[k]))
                out = c.fmu.getReal(c_out)
                rows[k] = y + out
                p.fmu.setReal(u_ref, [out[i_cmd]])
                t = k * p.dt
                p.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=p.dt)
                c.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=c.dt)
        finally:
            p.close()
            c.close()
    channels = {"time": np.arange(ag.size) * p.dt}
    channels.update({n: rows[:, i] for i, n in enumerate(p.outputs + c.outputs)})
    return Response(channels, kind=kind, mode=CONTROLLER_MODES[kind], dt=p.dt, rig=rig)


__all__ = ["BINARY", "KINDS", "MAX_NAME", "binary_path", "cosimulate", "export_fmu", "model_description",
           "settings"]
