# cmake -D SH_BUILD_DIR=... -D SH_SOURCE_DIR=... -D SH_WORK_DIR=... -D SH_GENERATOR=... -P run_packaging_test.cmake
# Installs the built project (component dev: headers, library, CMake package)
# into a fresh prefix, then configures, builds and runs tests/packaging against it.
foreach(var SH_BUILD_DIR SH_SOURCE_DIR SH_WORK_DIR SH_GENERATOR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "${var} not set")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "failed (${rc}): ${cmd}")
  endif()
endfunction()

set(prefix ${SH_WORK_DIR}/prefix)
file(REMOVE_RECURSE ${SH_WORK_DIR})
run(${CMAKE_COMMAND} --install ${SH_BUILD_DIR} --prefix ${prefix} --component dev)
foreach(f include/servohydraulics/plant.hpp include/servohydraulics/rig.hpp)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
run(${CMAKE_COMMAND} -S ${SH_SOURCE_DIR}/tests/packaging -B ${SH_WORK_DIR}/build -G ${SH_GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} -DSH_EXPECTED_PREFIX=${prefix}
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run(${CMAKE_COMMAND} --build ${SH_WORK_DIR}/build)
run(${SH_WORK_DIR}/build/consumer)
