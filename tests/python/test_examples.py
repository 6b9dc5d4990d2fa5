"""The examples run: the C++ examples (01_plant_step, 02_rpsd_controller, ...) build
against an INSTALLED package (cmake --install into a temporary prefix, then
find_package(servohydraulics)) and keep a 2 kHz loop on the host clock; the
Python examples run, the pairs with the same numbers as their C++ twins.

Oracles: the displacement loop is, at 1 Hz, the first-order lag of Eq (13)
(omega_c = K_v C_F K_s G_p / A), so a 10 mm sine comes out at
10 mm * omega_c / sqrt(omega^2 + omega_c^2); the load cell then carries
|k - m omega^2| x (spring and inertia of the structure in phase opposition).
The C++ program and the Python binding step the same library with the same
commands, so their physical results agree to the printed digits.  The RPsD
pair's oracles: the held displacement P/k of the modelled structure and its
damped natural frequency sqrt(k/m_m) sqrt(1 - zeta^2) / 2 pi (Eq 15).

The build reuses a configured build tree when one is at hand ($SH_BUILD_DIR,
$SERVOHYDRAULICS_CORE_DIR or build/ctest of scripts/run.sh test), otherwise
configures a library-only build in build/examples-test.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import servohydraulics as sh

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def parse(stdout: str) -> dict[str, float]:
    out = {}
    for line in stdout.splitlines():
        key, sep, value = line.partition("=")
        if sep and " " not in key:
            try:
                out[key] = float(value.split()[0])
            except ValueError:
                pass
    return out


def first_order_amplitude(amplitude: float, frequency: float) -> float:
    rig = sh.zhao2003()
    wc = rig.K_v * rig.C_F_disp * rig.K_s * rig.G_p / rig.A  # Eq (13) [rad/s]
    w = 2 * math.pi * frequency
    return amplitude * wc / math.hypot(w, wc)


def _run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    assert res.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{res.stdout[-3000:]}\n{res.stderr[-3000:]}"
    return res


def _build_tree(cmake: str) -> Path:
    for cand in (os.environ.get("SH_BUILD_DIR"), os.environ.get("SERVOHYDRAULICS_CORE_DIR"),
                 str(ROOT / "build" / "ctest")):
        if cand and (Path(cand) / "CMakeCache.txt").exists():
            return Path(cand)
    b = ROOT / "build" / "examples-test"
    gen = ["-G", "Ninja"] if shutil.which("ninja") else []
    _run([cmake, "-S", str(ROOT), "-B", str(b), *gen, "-DCMAKE_BUILD_TYPE=Release"])
    return b


@pytest.fixture(scope="module")
def cpp_examples(tmp_path_factory) -> Path:
    cmake = shutil.which("cmake")
    if cmake is None:
        pytest.skip("cmake is not installed")
    tree = _build_tree(cmake)
    _run([cmake, "--build", str(tree), "--target", "servohydraulics_core", "-j", "2"])
    tmp = tmp_path_factory.mktemp("example")
    prefix = tmp / "prefix"
    _run([cmake, "--install", str(tree), "--prefix", str(prefix), "--component", "dev"])
    gen = ["-G", "Ninja"] if shutil.which("ninja") else []
    _run([cmake, "-S", str(EXAMPLES), "-B", str(tmp / "build"), *gen, "-DCMAKE_BUILD_TYPE=Release",
          f"-DCMAKE_PREFIX_PATH={prefix}", "-DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF"])
    _run([cmake, "--build", str(tmp / "build")])
    cache = (tmp / "build" / "CMakeCache.txt").read_text()
    assert str(prefix) in cache  # found the installed package, not a build tree
    return tmp / "build"


@pytest.fixture(scope="module")
def controller(cpp_examples) -> Path:
    return cpp_examples / "01_plant_step"


def test_cpp_controller_keeps_a_2khz_loop_with_sane_physics(controller):
    res = _run([str(controller), "1.0", "0.01", "1.0"], timeout=60)
    s = parse(res.stdout)
    assert s["steps"] == 2000
    assert s["simulated_time_s"] == pytest.approx(1.0, abs=1e-9)
    assert 0 <= s["deadline_misses"] <= s["steps"]
    assert s["solver_failures"] == 0
    assert 0 < s["step_us_median"] <= s["step_us_p99"] <= s["step_us_p999"] <= s["step_us_max"]
    # Second half: the start-up transient (time constant 1/omega_c ~ 80 ms) is gone.
    x = first_order_amplitude(0.01, 1.0)
    assert s["steady_peak_displacement_mm"] == pytest.approx(1e3 * x, rel=0.05)
    rig = sh.zhao2003()
    f = math.hypot(rig.k - rig.m * (2 * math.pi) ** 2, rig.c * 2 * math.pi) * x
    assert s["steady_peak_force_kN"] == pytest.approx(1e-3 * f, rel=0.1)
    assert s["peak_displacement_mm"] >= s["steady_peak_displacement_mm"]


def test_cpp_rk4_option_runs(controller):
    s = parse(_run([str(controller), "0.2", "0.01", "1.0", "rk4"], timeout=60).stdout)
    assert s["steps"] == 400 and s["solver_failures"] == 0


def test_cpp_controller_rejects_bad_arguments(controller):
    res = subprocess.run([str(controller), "-1"], capture_output=True, text=True, timeout=30)
    assert res.returncode == 2 and "usage" in res.stderr


def run_example(name: str, *args: str) -> str:
    # The same servohydraulics this test process imports: the installed package,
    # or a dev build through the caller's PYTHONPATH / SERVOHYDRAULICS_CORE_DIR.
    env = dict(os.environ)
    env["MPLBACKEND"] = "Agg"
    return _run([sys.executable, str(EXAMPLES / name), *args], env=env, timeout=120).stdout


def test_python_plant_step_matches_cpp(controller):
    py = parse(run_example("01_plant_step.py", "1.0"))
    cpp = parse(_run([str(controller), "1.0", "0.01", "1.0"], timeout=60).stdout)
    assert py["steps"] == 2000
    assert py["peak_displacement_mm"] == pytest.approx(cpp["peak_displacement_mm"], abs=1e-4)
    assert py["peak_force_kN"] == pytest.approx(cpp["peak_force_kN"], abs=1e-4)


def g_xu(frequency: float) -> float:
    """|G_xu(j omega)| of Eq (12): the linearised displacement loop (valve
    dynamics neglected), moving mass = structure + piston."""
    r = sh.zhao2003()
    s = 2j * math.pi * frequency
    gain = r.A * r.K_v * r.C_F_disp * r.K_s * r.G_p
    m = r.m + r.m_p
    return abs(gain / ((r.C_l + r.K_a * s) * (r.k + r.c * s + m * s * s) + r.A**2 * s + gain))


def test_rpsd_controller_pair_meets_its_oracles_and_agrees(cpp_examples):
    cpp = parse(_run([str(cpp_examples / "02_rpsd_controller")], timeout=60).stdout)
    py = parse(run_example("02_rpsd_controller.py"))
    assert cpp["steps"] == py["steps"] == 10000
    assert cpp["solver_failures"] == py["solver_failures"] == 0
    assert 0 <= cpp["deadline_misses"] <= cpp["steps"]
    assert cpp["step_us_median"] > 0.0  # step times are measured; their targets live in benchmarks/
    # Oracles computed here, not taken from the examples: the ramp's force is 1.6 % of k x 1 m
    # (Fig 9), so the held displacement is 16 mm, up to the residual oscillation of the ramp
    # (zeta = 2.5 %) over 1.6 periods; the free vibration is the modelled SDOF's damped frequency
    # (k of the rig, m_m and c_m of Table I), shifted by the loop's residual lag.
    rig, tm = sh.zhao2003(), sh._core.ZHAO2003_TEST_METHODS
    wn = math.sqrt(rig.k / tm.model.m_m)
    zeta = tm.model.c_m / (2.0 * math.sqrt(rig.k * tm.model.m_m))
    assert cpp["held_displacement_mm"] == pytest.approx(16.0, rel=0.05)
    assert cpp["free_frequency_Hz"] == pytest.approx(wn * math.sqrt(1 - zeta**2) / (2 * math.pi), rel=0.03)
    for key in ("held_displacement_mm", "peak_command_mm", "free_frequency_Hz", "final_calc_displacement_mm"):
        assert py[key] == pytest.approx(cpp[key], abs=2e-6), key


def test_cpp_rpsd_controller_rejects_bad_arguments(cpp_examples):
    res = subprocess.run([str(cpp_examples / "02_rpsd_controller"), "0"], capture_output=True, text=True, timeout=30)
    assert res.returncode == 2 and "usage" in res.stderr


def test_python_simulate_record_follows_eq12():
    s = parse(run_example("03_simulate_record.py"))
    assert s["amplitude_ratio_0.5Hz"] == pytest.approx(g_xu(0.5), rel=0.02)
    # 5 Hz: the valve lag and the flow/pressure nonlinearities start to show.
    assert s["amplitude_ratio_5Hz"] == pytest.approx(g_xu(5.0), rel=0.1)


def test_python_sweep_examples_run():
    out = run_example("04_sweep_gain_mass.py")
    assert "controller.G_p" in out and "structure.m" in out
    out = run_example("05_uncertainty.py", "4")
    s = parse(out.replace(" ", "\n"))
    assert s["runs"] == 4
    assert s["min"] <= s["rms_tracking_error_mm_mean"] <= s["max"]


def _building_first_floor_amplitude(frequency: float, acceleration: float) -> float:
    """Steady-state first-floor amplitude [m] of the example's shear building under a sine a_g."""
    from servohydraulics import rths

    case, w = rths.shear_building(), 2 * math.pi * frequency
    x = np.linalg.solve(case.K - w * w * case.M + 1j * w * case.C, -case.M @ np.ones(3) * acceleration)
    return float(abs(x[0]))


def test_cpp_user_controller_equals_the_builtin_and_tracks_the_building(cpp_examples):
    """examples/07_user_controller.cpp: a user's C++ TrackingController (PI + lead written
    out) gives the built-in sample controller's commands exactly, and the specimen follows
    the building's steady-state first-floor response (frequency-response oracle)."""
    s = parse(_run([str(cpp_examples / "07_user_controller"), "10"], timeout=60).stdout)
    assert s["ok"] == 1 and s["samples"] == 40960 and s["max_command_difference_m"] == 0.0
    assert s["steady_peak_displacement_mm"] == pytest.approx(1e3 * _building_first_floor_amplitude(2.0, 1.0), rel=0.02)
    assert 0 < s["pilead_step_us_median"] <= s["pilead_step_us_p99"]
    res = subprocess.run([str(cpp_examples / "07_user_controller"), "-1"], capture_output=True, text=True, timeout=30)
    assert res.returncode == 2 and "invalid seconds" in res.stderr


@pytest.mark.parametrize("rate", [2000, 4096])
def test_cpp_realtime_eft_is_paced_and_computes_what_the_unpaced_loop_computes(cpp_examples, rate):
    """examples/10_realtime_eft.cpp: the EFT loop on the wall-clock Pacer at 2 kHz and
    4096 Hz.  Pacing changes when a sample runs, not what it computes: the paced
    displacements equal the unpaced run_eft's exactly.  The timing figures are reported,
    not asserted (a shared machine misses deadlines), only their consistency."""
    s = parse(_run([str(cpp_examples / "10_realtime_eft"), str(rate), "0.5"], timeout=60).stdout)
    assert s["samples"] == round(0.5 * rate) and s["solver_failures"] == 0
    assert s["paced_vs_unpaced_max_diff_m"] == 0.0
    assert 0 <= s["deadline_misses"] <= s["samples"]
    for name in ("wakeup_latency", "compute"):
        q = [s[f"{name}_us_{p}"] for p in ("min", "p50", "p99", "p999", "max")]
        assert 0.0 <= q[0] and q == sorted(q)
    for bad in (["50"], ["2000", "-1"], ["2000", "1", "--fifo"], ["2000", "1", "--bogus"]):
        res = subprocess.run([str(cpp_examples / "10_realtime_eft"), *bad], capture_output=True, text=True, timeout=30)
        assert res.returncode == 2 and "usage" in res.stderr


def test_python_user_controller_equals_the_builtin():
    """examples/07_user_controller.py: PI + lead in pure Python (the core's converters)
    gives the built-in sample controller's commands and J exactly."""
    s = parse(run_example("07_user_controller.py"))
    assert s["builtin_ok"] == s["python_ok"] == 1 and s["same_J"] == 1 and s["max_command_difference_m"] == 0.0
    J = {k[len("python_"):]: v for k, v in s.items() if k.startswith("python_J")}
    assert len(J) == 9 and all(s[f"builtin_{k}"] == v for k, v in J.items())
    assert 0 < J["J1_delay_ms"] <= 12.0 and J["J2_rms_tracking_error_pct"] < 20.0


def test_cpp_user_controller_as_a_python_module(cpp_examples, tmp_path):
    """examples/07_user_controller_module.cpp: the C++ PiLead exposed by a small pybind11
    module (built as its comment says, against the installed library) is a
    rths.TrackingController that the benchmark runs in C++: the built-in's J and commands."""
    import sysconfig

    import pybind11

    prefix = cpp_examples.parent / "prefix"
    lib = next(prefix.glob("lib*/libservohydraulics.a"))
    so = tmp_path / f"my_controllers{sysconfig.get_config_var('EXT_SUFFIX')}"
    eigen = [f"-I{p}" for p in ("/usr/include/eigen3",) if Path(p).is_dir()]
    _run([os.environ.get("CXX", "c++"), "-O2", "-shared", "-fPIC", "-std=c++17", f"-I{pybind11.get_include()}",
          f"-I{sysconfig.get_paths()['include']}", f"-I{prefix / 'include'}", *eigen, f"-I{EXAMPLES}",
          str(EXAMPLES / "07_user_controller_module.cpp"), str(lib), "-o", str(so)], timeout=300)
    code = textwrap.dedent(f"""
        import sys; sys.path.insert(0, {str(tmp_path)!r})
        import numpy as np
        from servohydraulics import rths
        import my_controllers
        c = my_controllers.PiLead()
        assert isinstance(c, rths.TrackingController)
        case, rec = rths.embedded_case(1), rths.synthetic_record(duration=8.0)
        a = rths.run_trial(case, rec, c, keep_signals=True)
        b = rths.run_trial(case, rec, "sample", keep_signals=True)
        print("same_J=%d" % (a.J == b.J))
        print("max_command_difference_m=%g" % np.max(np.abs(a.signals["command"] - b.signals["command"])))
    """)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    if "unknown base type" in res.stderr:  # another pybind11 ABI than the package's: a setup limit, said in the doc
        pytest.skip("the package's _core was built with another pybind11 ABI than this one: " + res.stderr[-300:])
    assert res.returncode == 0, res.stderr[-3000:]
    s = parse(res.stdout)
    assert s["same_J"] == 1 and s["max_command_difference_m"] == 0.0


def test_rpsd_frame_example_follows_the_frame_without_servo():
    """examples/08_rpsd_frame.py: RPsD of a 3-storey frame (linear M, C, K numerical substructure,
    the rig's structure as the first storey).  Oracle: the whole frame without the servo-system;
    with ATS tracking the first-floor displacement follows it (6.5 % NRMS at 10 s), the paper's
    68 ms lead less well (29 %)."""
    s = parse(run_example("08_rpsd_frame.py", "10").replace(" ", "\n"))
    assert s["exact_peak_mm"] > 1.0
    assert s["ats_error_pct"] < 10.0
    assert s["ats_error_pct"] < s["paper_error_pct"]
    assert abs(s["ats_peak_mm"] / s["exact_peak_mm"] - 1.0) < 0.1


def test_rpsd_opensees_example_matches_the_linear_substructure():
    """examples/09_rpsd_opensees.py: the same frame with its numerical part in OpenSeesPy; the
    linear OpenSees model gives the linear substructure's answer (within OpenSees' own central
    difference: 3.9 % NRMS), the yielding one a different response."""
    pytest.importorskip("openseespy")
    s = parse(run_example("09_rpsd_opensees.py", "5").replace(" ", "\n"))
    assert s["opensees_linear_vs_linear_pct"] < 8.0
    assert s["opensees_yielding_vs_linear_pct"] > 20.0
    assert s["opensees_yielding_peak_mm"] > 0.5
