"""FMU export (issue 15): fmpy validates and runs the FMUs, and their outputs
equal the library's on the same inputs.

The oracle is the library itself through its own entry points (sh.simulate,
sh.run_eft, sh.run_rpsd): the FMU runs the same core, so equality is the
contract (1e-9 relative; the figures are printed by
benchmarks/fmu_bench.py --equality).  The controller FMUs are driven in a loop
with a plant FMU, as a co-simulation master would (Gauss-Seidel: the plant's
outputs at t_k -> the controller's inputs; the controller's command at t_k ->
the plant; both step).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
import zipfile

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402
from fmu_support import instantiate  # noqa: E402

import servohydraulics as sh  # noqa: E402
from servohydraulics import _core  # noqa: E402
from servohydraulics.fmu import cosimulate  # noqa: E402

DT = 5e-4
PLANT_OUT = [name for name, _unit in _core.PLANT_CHANNELS if name != "time"]
RTOL = 1e-9


class Slave:
    """An FMU instance driven by name through fmpy's FMU2Slave; ``logs``, if given,
    receives the FMU's log messages."""

    def __init__(self, path, workdir, instance="inst", logs=None, start=True):
        # an extracted FMU is used as it is (re-extracting would overwrite a loaded binary)
        self.dir = str(path) if os.path.isdir(path) else extract(str(path), unzipdir=str(workdir))
        self.md = read_model_description(self.dir)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.var = {v.name: v for v in self.md.modelVariables}
        self.fmu, self._callbacks = instantiate(self.dir, self.md, instance, logs)  # callbacks kept alive
        self.t = 0.0
        if start:
            self.start()

    def start(self, **values):
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.set(**values)
        self.fmu.exitInitializationMode()

    def set(self, **values):
        for k, v in values.items():
            name = k.replace("__", ".")
            t = self.var[name].type
            if t == "Real":
                self.fmu.setReal([self.vr[name]], [float(v)])
            elif t == "Boolean":
                self.fmu.setBoolean([self.vr[name]], [bool(v)])
            else:
                self.fmu.setInteger([self.vr[name]], [int(v)])

    def get(self, names):
        return self.fmu.getReal([self.vr[n] for n in names])

    def step(self, h=DT):
        self.fmu.doStep(currentCommunicationPoint=self.t, communicationStepSize=h)
        self.t += h

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def _rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


def _equal(fmu_rows: dict, ref, names):
    worst = {}
    for n in names:
        r = _rel(fmu_rows[n], ref.channels[n] if hasattr(ref, "channels") else ref[n])
        worst[n] = r
        assert r <= RTOL, f"{n}: FMU differs from the library by {r:.3g} (relative)"
    return worst


@pytest.fixture(scope="module")
def rig():
    return sh.zhao2003()


@pytest.fixture(scope="module")
def fmus(rig, tmp_path_factory):
    d = tmp_path_factory.mktemp("fmus")
    return {"plant_disp": sh.export_fmu(rig, d / "plant_disp.fmu", kind="plant", mode="displacement"),
            "plant_force": sh.export_fmu(rig, d / "plant_force.fmu", kind="plant", mode="force"),
            "eft": sh.export_fmu(rig, d / "eft.fmu", kind="eft"),
            "rpsd": sh.export_fmu(rig, d / "rpsd.fmu", kind="rpsd"),
            "dir": d}


def run_plant(path, workdir, u, **values):
    s = Slave(path, workdir, start=False)
    s.start(**values)
    rows = {n: [] for n in PLANT_OUT}
    for k in range(len(u)):
        for n, v in zip(PLANT_OUT, s.get(PLANT_OUT)):
            rows[n].append(v)
        if k + 1 < len(u):
            s.set(command=u[k])
            s.step()
    s.close()
    return rows


def test_model_descriptions_validate(fmus):
    for key in ("plant_disp", "plant_force", "eft", "rpsd"):
        assert validate_fmu(str(fmus[key])) == [], key


def test_fmu_layout_and_resources(rig, fmus):
    with zipfile.ZipFile(fmus["plant_disp"]) as z:
        names = set(z.namelist())
        assert {"modelDescription.xml", "resources/rig.toml", "resources/fmu.toml",
                "binaries/linux64/servohydraulics_plant.so"} <= names
        (fmus["dir"] / "rig_from_fmu.toml").write_bytes(z.read("resources/rig.toml"))
    assert sh.load_rig(fmus["dir"] / "rig_from_fmu.toml") == rig  # the rig, readable by the library


def test_parameters_come_from_the_core_tables(fmus):
    md = read_model_description(str(fmus["plant_disp"]))
    v = {x.name: x for x in md.modelVariables}
    for p in _core.RIG_PARAMETERS:
        x = v[f"{p['section']}.{p['key']}"]
        assert x.causality == "parameter"
        assert x.variability == ("tunable" if p["section"] == "controller" else "fixed")
    for e in _core.EFFECTS:
        assert v[f"effects.{e['key']}"].type == "Boolean"
    for name, unit in _core.PLANT_CHANNELS:
        if name != "time":
            assert v[name].causality == "output"
            assert v[name].unit == (None if unit == "-" else unit)
    assert v["command"].unit == "m" and v["command"].causality == "input"
    # Every enum parameter's items are the core's name table (enum_name.hpp), in the enum's order,
    # and every SolverOptions field (kSolverOptionFields) is a parameter.
    tables = {"solver.method": _core.METHOD_NAMES, "solver.restart": _core.RESTART_NAMES}
    for name, table in tables.items():
        assert [i.name for i in v[name].declaredType.items] == [n for n, _ in table]
        assert [int(e) for _, e in table] == list(range(len(table)))
    assert {f["name"] for f in _core.SOLVER_OPTION_FIELDS} == {n[len("solver."):] for n in v if n.startswith("solver.")}
    for key, table in (("eft", {"eft.compensation": _core.COMPENSATION_NAMES}),
                       ("rpsd", {"rpsd.scheme": _core.SCHEME_NAMES[:2],
                                 "rpsd.restoring_force": _core.RESTORING_FORCE_NAMES,
                                 "rpsd.force_measurement": _core.FORCE_MEASUREMENT_NAMES})):
        cv = {x.name: x for x in read_model_description(str(fmus[key])).modelVariables}
        for name, names in table.items():
            assert [i.name for i in cv[name].declaredType.items] == [n for n, _ in names]


def test_plant_fmu_takes_every_solver_option(rig, tmp_path):
    """The FMU integrates with the options it was exported with, all of them: with CVODE at a
    coarse atol_fraction and order 2 (fields the FMU once dropped) it still equals sh.simulate."""
    options = sh.solver_options(method="cvode", rtol=1e-6, atol_fraction=0.5, max_order=2)
    path = sh.export_fmu(rig, tmp_path / "options.fmu", solver_options=options)
    v = {x["name"]: x["start"] for x in _core.fmu_variables("plant", "displacement", rig, DT, 0.0, options,
                                                              _core.EftConfig(), _core.RpsdConfig())}
    for f in _core.SOLVER_OPTION_FIELDS:
        value = getattr(options, f["name"])
        assert v["solver." + f["name"]] == (value if isinstance(value, float) else float(int(value))), f["name"]
    u = 0.01 * np.sin(2 * np.pi * 2.0 * np.arange(400) * DT)
    ref = sh.simulate(rig, "displacement", u, DT, options=options)
    dropped = sh.simulate(rig, "displacement", u, DT, options=sh.solver_options(method="cvode", rtol=1e-6))
    assert _rel(ref.channels["pressure"], dropped.channels["pressure"]) > 1e3 * RTOL  # the options matter
    _equal(run_plant(path, tmp_path, u), ref, PLANT_OUT)


@pytest.mark.parametrize("mode", ["displacement", "force"])
def test_plant_fmu_equals_simulate(rig, fmus, tmp_path, mode):
    n = 600
    t = np.arange(n) * DT
    amp = 0.01 if mode == "displacement" else 20e3
    u = amp * np.sin(2 * np.pi * 2.0 * t)
    ref = sh.simulate(rig, mode, u, DT)
    rows = run_plant(fmus["plant_disp" if mode == "displacement" else "plant_force"], tmp_path, u)
    _equal(rows, ref, PLANT_OUT)


def test_plant_fmu_rk4_and_multi_sample_steps(rig, tmp_path):
    """The integrator parameter, and doStep over 4 samples = 4 held samples of sh.simulate."""
    path = sh.export_fmu(rig, tmp_path / "rk4.fmu", solver_options=sh.solver_options("rk4"))
    n, m = 200, 4
    u_coarse = 0.005 * np.sin(2 * np.pi * 3.0 * np.arange(n) * m * DT)
    ref = sh.simulate(rig, "displacement", np.repeat(u_coarse, m), DT, options=sh.solver_options("rk4"))
    s = Slave(path, tmp_path / "x")
    got = []
    for k in range(n):
        got.append(s.get(["displacement"])[0])
        s.set(command=u_coarse[k])
        s.step(m * DT)
    s.close()
    assert _rel(got, ref.displacement[::m]) <= RTOL


def test_eft_fmu_with_plant_fmu_equals_run_eft(rig, fmus):
    n = 800
    ag = 3.0 * np.sin(2 * np.pi * 1.5 * np.arange(n) * DT)
    ref = sh.run_eft(rig, ag, dt=DT)
    res = cosimulate(fmus["plant_force"], fmus["eft"], ag)
    outputs = ["effective_force", "compensation", "compensation_opening", "command"]
    assert set(res.channels) == {"time", *PLANT_OUT, *outputs}
    _equal(res.channels, ref, PLANT_OUT + outputs)
    _same_response(res, ref, outputs)


def _same_response(res, ref, outputs):
    """cosimulate's Response carries what the library's does: kind, mode, dt, units, the rig."""
    assert isinstance(res, sh.Response) and res.success and res.status == "ok"
    assert (res.kind, res.mode, res.dt, len(res)) == (ref.kind, ref.mode, ref.dt, len(ref))
    np.testing.assert_array_equal(res.time, ref.time)
    assert {n: res.units[n] for n in PLANT_OUT + outputs} == {n: ref.units[n] for n in PLANT_OUT + outputs}
    assert sh.rig_to_dict(res.rig) == sh.rig_to_dict(ref.rig)
    assert list(res.to_pandas().columns) == list(res.channels)


def test_rpsd_fmu_with_plant_fmu_equals_run_rpsd(rig, tmp_path):
    n = 800
    ag = 2.0 * np.sin(2 * np.pi * 1.2 * np.arange(n) * DT)
    pe = np.where(np.arange(n) < 200, 1e3, 0.0)
    kw = {"restoring_force": "measured_force_corrected", "scheme": "explicit_newmark"}
    ref = sh.run_rpsd(rig, ag, external_force=pe, dt=DT, physical_mass_fraction=0.02, **kw)
    phys = ref.rig  # the physical rig of the simulated test
    plant = sh.export_fmu(phys, tmp_path / "p.fmu")
    ctrl = sh.export_fmu(phys, tmp_path / "r.fmu", kind="rpsd", **kw)
    res = cosimulate(plant, ctrl, ag, external_force=pe)
    outputs = ["measured_restoring_force", "restoring_force", "calc_displacement", "calc_velocity",
               "calc_acceleration", "target_displacement", "command"]
    assert set(res.channels) == {"time", *PLANT_OUT, *outputs}
    _equal(res.channels, ref, PLANT_OUT + outputs)
    _same_response(res, ref, outputs)
    with pytest.raises(ValueError, match=r"invalid controller = .*p\.fmu': an FMU of kind 'plant', expected 'eft' or "
                                         r"'rpsd'"):
        cosimulate(plant, plant, ag[:10])
    with pytest.raises(ValueError, match=r"invalid plant = .*r\.fmu': an FMU of kind 'rpsd', expected 'plant'"):
        cosimulate(ctrl, ctrl, ag[:10])


def test_output_reads_do_not_advance_the_controller(rig, fmus, tmp_path):
    """Reading the outputs twice (or setting the inputs twice) computes the same sample."""
    c = Slave(fmus["eft"], tmp_path)
    c.set(ground_acceleration=1.0, sensors__velocity=0.01)
    a = c.get(["command", "compensation"])
    c.set(ground_acceleration=1.0, sensors__velocity=0.01)
    assert c.get(["command", "compensation"]) == a == c.get(["command", "compensation"])
    c.close()


def test_two_instances_are_independent(rig, fmus, tmp_path):
    """Two instances in one process, stepped alternately, equal two separate runs."""
    n = 300
    t = np.arange(n) * DT
    u1, u2 = 0.01 * np.sin(2 * np.pi * 2 * t), -0.004 * np.cos(2 * np.pi * 5 * t)
    unzipped = extract(str(fmus["plant_disp"]), unzipdir=str(tmp_path / "a"))
    a = Slave(unzipped, None, instance="a")
    b = Slave(unzipped, None, instance="b")  # the same binary file
    xa, xb = [], []
    for k in range(n):
        xa.append(a.get(["displacement"])[0])
        xb.append(b.get(["displacement"])[0])
        a.set(command=u1[k])
        b.set(command=u2[k])
        a.step()
        b.step()
    assert _rel(xa, sh.simulate(rig, "displacement", u1, DT).displacement) <= RTOL
    assert _rel(xb, sh.simulate(rig, "displacement", u2, DT).displacement) <= RTOL


def test_tunable_gain(rig, fmus, tmp_path):
    """controller.G_p is tunable: at G_p = 0 the valve drive is zero from the next sample on."""
    s = Slave(fmus["plant_disp"], tmp_path)
    for _ in range(20):
        s.set(command=0.005)
        s.step()
    assert abs(s.get(["drive"])[0]) > 0.01
    s.set(controller__G_p=0.0)
    s.step()
    assert s.get(["drive"])[0] == 0.0
    s.close()


def test_errors_are_fmi_status_with_a_message(rig, fmus, tmp_path):
    logs: list[str] = []
    s = Slave(fmus["plant_disp"], tmp_path / "a", logs=logs, start=False)
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    s.set(actuator__K_a=-1.0)
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    assert any("K_a" in m and "-1" in m for m in logs), logs
    # a fixed parameter after initialisation, a step that is not a whole number of samples
    s.fmu.reset()
    s.start()
    logs.clear()
    with pytest.raises(FMICallException):
        s.set(structure__m=1.0)
    assert any("structure.m is a fixed parameter" in m for m in logs), logs
    with pytest.raises(FMICallException):
        s.step(1.5 * DT)
    assert any("whole number" in m and "communicationStepSize" in m for m in logs), logs
    with pytest.raises(FMICallException):
        s.set(solver__method=7)  # fixed, and out of range
    s.close()


def test_solver_failure_is_an_error_with_its_time(rig, tmp_path):
    logs: list[str] = []
    path = sh.export_fmu(rig, tmp_path / "f.fmu", solver_options=sh.solver_options(max_steps_per_sample=1))
    s = Slave(path, tmp_path / "f", logs=logs)
    with pytest.raises(FMICallException):
        for _ in range(50):
            s.set(command=0.05)
            s.step()
    assert any("plant step failed at t = " in m for m in logs), logs
    with pytest.raises(FMICallException):  # no further step until fmi2Reset
        s.step()


def test_simulate_fmu_validate_true(rig, fmus):
    """fmpy's own master with validation: a held command step equals sh.simulate."""
    n = 201
    u = np.full(n, 0.002)
    sig = np.array([(0.0, 0.002), ((n - 1) * DT, 0.002)], dtype=[("time", float), ("command", float)])
    res = fmpy.simulate_fmu(str(fmus["plant_disp"]), validate=True, stop_time=(n - 1) * DT, output_interval=DT,
                            input=sig, output=PLANT_OUT)
    ref = sh.simulate(rig, "displacement", u, DT)
    assert len(res) == n
    _equal({k: res[k] for k in PLANT_OUT}, ref, PLANT_OUT)


def test_binary_is_self_contained(fmus, tmp_path):
    """No SUNDIALS, Python or C++ runtime library needed; only fmi2* exported; loads with a clean environment."""
    readelf = shutil.which("readelf")
    if readelf is None:
        pytest.skip("readelf (binutils) not installed")
    with zipfile.ZipFile(fmus["plant_disp"]) as z:
        z.extractall(tmp_path / "u")
    so = tmp_path / "u" / "binaries" / "linux64" / "servohydraulics_plant.so"
    dyn = subprocess.run([readelf, "-d", str(so)], capture_output=True, text=True, check=True).stdout
    needed = [line.split("[")[1].rstrip("]") for line in dyn.splitlines() if "(NEEDED)" in line]
    assert needed and all(n.split(".so")[0] in ("libc", "libm", "ld-linux-x86-64", "libdl", "libpthread")
                          for n in needed), needed
    syms = subprocess.run([readelf, "--dyn-syms", "-W", str(so)], capture_output=True, text=True, check=True).stdout
    exported = {ln.split()[7] for ln in syms.splitlines()
                if len(ln.split()) >= 8 and ln.split()[6] != "UND" and ln.split()[4] == "GLOBAL"}
    assert exported and all(s.startswith("fmi2") for s in exported), sorted(exported)[:10]
    script = textwrap.dedent(f"""
        import fmpy
        r = fmpy.simulate_fmu({str(fmus['plant_disp'])!r}, stop_time=0.01, output_interval={DT},
                              start_values={{'command': 0.001}}, output=['displacement'])
        print(len(r), r['displacement'][-1])
    """)
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}  # no LD_LIBRARY_PATH, no PYTHONPATH
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    count, x = out.stdout.split()
    assert int(count) == 21 and 0.0 < float(x) < 0.001


def test_export_rejects_bad_arguments(rig, tmp_path):
    with pytest.raises(ValueError, match="kind"):
        sh.export_fmu(rig, tmp_path / "a.fmu", kind="valve")
    with pytest.raises(ValueError, match="mode"):
        sh.export_fmu(rig, tmp_path / "a.fmu", kind="eft", mode="displacement")
    with pytest.raises(ValueError, match="lead_T"):
        sh.export_fmu(rig, tmp_path / "a.fmu", kind="eft", lead_T=-1.0)
    with pytest.raises(ValueError, match="name"):
        sh.export_fmu(rig, tmp_path / "a.fmu", name="not an identifier")
    assert not (tmp_path / "a.fmu").exists()
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".part")]


def test_cli_writes_an_fmu(rig, tmp_path):
    sh.save_rig(rig, tmp_path / "rig.toml")
    out = subprocess.run([sys.executable, "-m", "servohydraulics", "fmu", "--rig", str(tmp_path / "rig.toml"),
                          "--mode", "force", "--kind", "plant", "--out", str(tmp_path / "p.fmu")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert validate_fmu(str(tmp_path / "p.fmu")) == []
    md = read_model_description(str(tmp_path / "p.fmu"))
    assert {v.name: v for v in md.modelVariables}["command"].unit == "N"
    out = subprocess.run([sys.executable, "-m", "servohydraulics", "fmu", "--kind", "eft", "--set", "lead_T=0.002",
                          "--set", "compensation=nonlinear", "--out", str(tmp_path / "e.fmu")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    v = {x.name: x for x in read_model_description(str(tmp_path / "e.fmu")).modelVariables}
    assert float(v["eft.lead_T"].start) == 0.002 and int(v["eft.compensation"].start) == 2


def test_rig_details_travel_through_the_resources(rig, tmp_path):
    """A tabulated flow curve (arrays), an effect switched off (Boolean), x0 and dt: the FMU equals sh.simulate."""
    r = sh.copy_rig(rig)
    fc = _core.FlowCurve()
    fc.kind = _core.FlowCurve.Kind.Table
    fc.opening, fc.flow = [0.0, 0.1, 0.5, 1.0], [0.0, 0.1, 0.42, 0.6]
    r.flow_curve = fc
    r.effects.coulomb_friction = False
    r.k = 612345.678901234
    dt, x0 = 1e-3, 0.004
    path = sh.export_fmu(r, tmp_path / "t.fmu", dt=dt, x0=x0)
    u = x0 + 0.02 * np.sin(2 * np.pi * 5.0 * np.arange(400) * dt)  # spool beyond 10 %: the curve matters
    ref = sh.simulate(r, "displacement", u, dt, x0=x0)
    assert np.max(np.abs(ref.spool)) > 0.12
    s = Slave(path, tmp_path / "t")
    got = []
    for k in range(u.size):
        got.append(s.get(["displacement"])[0])
        s.set(command=u[k])
        s.step(dt)
    s.close()
    assert _rel(got, ref.displacement) <= RTOL
    assert s.var["effects.coulomb_friction"].start in ("false", False)


def test_mr_damper_law_travels_through_the_resources(rig, tmp_path):
    """The MR damper's field input and law (rig keys whose value is a name: Enumeration parameters):
    a current-driven damper under the thesis' law at 0.5 A equals sh.simulate in the FMU."""
    from servohydraulics.identification.baselines import thesis_law_keys

    r = sh.rig_from_dict({"specimen": {**thesis_law_keys(), "mr_current": 0.5}}, base=rig)
    r.effects.mr_damper = True
    dt = 1e-3
    path = sh.export_fmu(r, tmp_path / "mr.fmu", dt=dt)
    u = 0.005 * np.sin(2 * np.pi * 2.0 * np.arange(400) * dt)
    ref = sh.simulate(r, "displacement", u, dt)
    s = Slave(path, tmp_path / "mr")
    assert s.var["specimen.mr_input"].type == "Enumeration" and s.var["specimen.mr_law"].type == "Enumeration"
    got = []
    for k in range(u.size):
        got.append(s.get(["force"])[0])
        s.set(command=u[k])
        s.step(dt)
    s.close()
    assert _rel(got, ref.force) <= RTOL
    spencer = sh.copy_rig(r)
    spencer.mr_law, spencer.mr_alpha_c, spencer.mr_bw_decay = _core.MrLaw.Spencer, 0.0, 0.0
    assert _rel(sh.simulate(spencer, "displacement", u, dt).force, ref.force) > 1e-3  # the law matters here
