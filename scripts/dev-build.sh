#!/usr/bin/env bash
# Incremental developer build in build/<name> (C++ library, tests, Python module).
# Use the result without reinstalling:
#   scripts/dev-build.sh dev && PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python -c "import servohydraulics"
set -euo pipefail
name=${1:-dev}
shift || true
root=$(cd "$(dirname "$0")/.." && pwd)
py=${PYTHON:-python3}
cmake -S "$root" -B "$root/build/$name" -G Ninja -DSH_BUILD_PYTHON=ON -DSH_BUILD_TESTS=ON -DSH_BUILD_FMU=ON \
  -DPython_EXECUTABLE="$(command -v "$py")" -Dpybind11_DIR="$("$py" -c 'import pybind11; print(pybind11.get_cmake_dir())')" \
  "$@" >/dev/null
cmake --build "$root/build/$name" -j 2
