#!/usr/bin/env bash
# The README's entry point.  On a fresh Debian machine (root, Python and a C++
# compiler present) it installs what it needs itself, then:
#   scripts/run.sh demo    the main job on built-in defaults (plots + summaries in demo_out/)
#   scripts/run.sh test    ruff, then all tests: C++ (ctest) and Python (pytest), but those marked slow
#   scripts/run.sh test-all  the same with the slow diagnosis tests (minutes each)
#   scripts/run.sh bench   the step-time benchmarks (docs/benchmarks.md)
#   scripts/run.sh sanitize  the C++ tests (with the SUNDIALS failure injection), the FMU binary
#                          through its C ABI (a normal and a hostile host) and a short Python
#                          smoke run (RTHS with a Python controller, identify, the FMU export
#                          through fmpy) under AddressSanitizer, UBSan and LeakSanitizer
#                          (docs/robustness.md)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
venv=${VENV:-"$root/.venv"}
py=${PYTHON:-python3}
jobs=${JOBS:-2}

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
  echo "need root (or sudo) to install: $*" >&2; exit 1; fi; }

system_deps() {
  # Debian packages: SUNDIALS (CVODE) and Eigen; Python headers and venv if missing.
  local need=()
  dpkg -s libsundials-dev >/dev/null 2>&1 || need+=(libsundials-dev)
  dpkg -s libeigen3-dev >/dev/null 2>&1 || need+=(libeigen3-dev)
  "$py" -c 'import sysconfig, os, sys; sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))' \
    || need+=(python3-dev)
  "$py" -m venv --help >/dev/null 2>&1 && "$py" -c 'import ensurepip' 2>/dev/null || need+=(python3-venv)
  if [ ${#need[@]} -gt 0 ]; then
    echo "installing Debian packages: ${need[*]}"
    as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq --no-install-recommends "${need[@]}"
  fi
}

# A digest of everything the installed package is built from: the C++ core, the bindings, the
# Python layer and the build files (pyproject.toml holds the extras).  Caches and built modules
# are left out, so a test run or a dev build does not change it.
source_digest() {
  (cd "$root" && find cpp bindings python cmake CMakeLists.txt pyproject.toml -type f \
      ! -name '*.pyc' ! -name '*.so' ! -path '*/__pycache__/*' -print0 |
    LC_ALL=C sort -z | xargs -0 sha256sum | sha256sum | cut -d' ' -f1)
}

# The virtual environment with the package and its test extras.  The install (scikit-build-core
# builds the C++ core: minutes on two cores) runs only when the sources differ from the last
# successful install, recorded in $venv/.servohydraulics-sources, so `demo` then `test` build
# the package once.  SH_REINSTALL=1 forces it.
# `python_env tests` (the test commands) builds the package in build/ctest with the C++ tests
# (SH_BUILD_TESTS) and without pip's build isolation, so that cxx_tests finds that tree built and
# the core is compiled once, not twice (CI time).
python_env() {
  local with_tests=${1:-}
  [ -x "$venv/bin/python" ] || "$py" -m venv "$venv"
  local stamp="$venv/.servohydraulics-sources" digest
  digest=$(source_digest)
  if [ -z "${SH_REINSTALL:-}" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$digest" ] &&
      "$venv/bin/python" -c "import servohydraulics, pytest, ruff" 2>/dev/null; then
    echo "servohydraulics: installed in $venv from these sources already (SH_REINSTALL=1 reinstalls)"
    return
  fi
  rm -f "$stamp"
  "$venv/bin/python" -m pip install -q --upgrade pip
  # Build tools for the C++ tests, then the package itself with its test extras.
  "$venv/bin/python" -m pip install -q cmake ninja "pybind11>=2.12"
  if [ -n "$with_tests" ]; then
    # The build requirements of pyproject.toml's [build-system], in the venv (no isolation).
    "$venv/bin/python" -m pip install -q "scikit-build-core>=0.10" "fmpy>=0.3.20"
    PATH="$venv/bin:$PATH" "$venv/bin/python" -m pip install -q --no-build-isolation \
      -C build-dir="$root/build/ctest" -C cmake.define.SH_BUILD_TESTS=ON "$root[test]"
  else
    "$venv/bin/python" -m pip install -q "$root[test]"
  fi
  echo "$digest" > "$stamp"
}

# Lint every Python file of the tree ([tool.ruff] in pyproject.toml); any finding fails the run.
lint() {
  "$venv/bin/ruff" check "$root/python" "$root/tests" "$root/benchmarks" "$root/evaluation" "$root/studies" \
    "$root/examples" "$root/scripts"
}

cxx_tests() {
  # The tree `python_env tests` built (configured again with the same settings: nothing to rebuild),
  # or a new one when the package was installed by `demo`.
  local b="$root/build/ctest"
  # SH_BUILD_FMU: the FMU binary and its C-ABI test (the FMI headers come from the venv's fmpy)
  "$venv/bin/cmake" -S "$root" -B "$b" -G Ninja -DSH_BUILD_TESTS=ON -DCMAKE_BUILD_TYPE=Release \
    -DSH_BUILD_FMU=ON -DPython_EXECUTABLE="$venv/bin/python" \
    -DCMAKE_MAKE_PROGRAM="$venv/bin/ninja" >/dev/null
  "$venv/bin/cmake" --build "$b" -j "$jobs"
  PATH="$venv/bin:$PATH" "$venv/bin/ctest" --test-dir "$b" --output-on-failure -j "$jobs"
}

# A small Debug build: the core, the FMU binary and the C++ tests at -O1 with ASan + UBSan (+ LSan,
# part of ASan on Linux), the Python module's glue at -O0 linked to them; nothing else (no packaging
# test, no examples).  Any report fails the run.
sanitize() {
  local b="$root/build/sanitize"
  local flags="-O1;-g;-fno-omit-frame-pointer;-fsanitize=address,undefined;-fno-sanitize-recover=all"
  local pybind; pybind=$("$venv/bin/python" -c 'import pybind11; print(pybind11.get_cmake_dir())')
  "$venv/bin/cmake" -S "$root" -B "$b" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O0 \
    -DSH_BUILD_TESTS=ON -DSH_BUILD_PYTHON=ON -DSH_BUILD_FMU=ON -DSH_SANITIZE="$flags" -DCMAKE_MAKE_PROGRAM="$venv/bin/ninja" \
    -DPython_EXECUTABLE="$venv/bin/python" -Dpybind11_DIR="$pybind" >/dev/null
  "$venv/bin/cmake" --build "$b" -j "$jobs"
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  # core: the C++ tests; fmu: test_fmu_binary, a host that dlopens the sanitized FMU binary.
  PATH="$venv/bin:$PATH" "$venv/bin/ctest" --test-dir "$b" --output-on-failure -j "$jobs" -L 'core|fmu'
  # Python smoke: the sanitized _core (and, through fmpy, the sanitized FMU binary the export copies)
  # inside an unsanitized interpreter (libasan preloaded).
  # The interpreter's own allocations at exit are not ours: leaks are checked by the C++ tests.
  # libstdc++ preloaded too: ASan must find the real __cxa_throw when it starts.
  local asan; asan="$(${CXX:-c++} -print-file-name=libasan.so) $(${CXX:-c++} -print-file-name=libstdc++.so)"
  LD_PRELOAD="$asan" ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 PYTHONPATH="$root/python" \
    SERVOHYDRAULICS_CORE_DIR="$b" "$venv/bin/python" "$root/tests/python/sanitize_smoke.py"
}

case "${1:-}" in
  demo)
    system_deps; python_env
    "$venv/bin/servohydraulics" demo --out "$root/demo_out"
    if "$venv/bin/servohydraulics" --help | grep -q reproduce; then
      "$venv/bin/servohydraulics" reproduce --out "$root/demo_out/reproduce"
    fi
    ;;
  test)
    system_deps; python_env tests
    lint
    cxx_tests
    # Run pytest from the tests directory so that the installed package is the one imported;
    # one worker process per core (pytest-xdist): the diagnosis tests dominate and are independent.
    # Tests marked slow (diagnosis runs of a minute or more each) are left to `test-all`.
    PATH="$venv/bin:$PATH" "$venv/bin/python" -m pytest "$root/tests/python" -q -p no:cacheprovider -n auto -m "not slow" \
      --durations=15
    ;;
  test-all)
    system_deps; python_env tests
    lint
    cxx_tests
    PATH="$venv/bin:$PATH" "$venv/bin/python" -m pytest "$root/tests/python" -q -p no:cacheprovider -n auto
    ;;
  bench)
    system_deps; python_env
    PATH="$venv/bin:$PATH" "$venv/bin/python" "$root/benchmarks/run.py"
    ;;
  sanitize)
    [ -x "$venv/bin/python" ] || { system_deps; python_env; }
    sanitize
    ;;
  *)
    echo "usage: scripts/run.sh demo|test|bench|sanitize" >&2
    exit 2
    ;;
esac
