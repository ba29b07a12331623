# ctest driver for the downstream project: install proxgen into a prefix,
# configure and build a user project against it, run it, then change the layout
# and check that the build regenerates the solver (Settings::mu follows it).
# Inputs: -DBUILD_DIR= (proxgen build tree) -DSOURCE_DIR= (proxgen sources) -DWORK_DIR= (scratch)
cmake_minimum_required(VERSION 3.22)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(LAST_OUTPUT "${out}${err}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
file(COPY "${SOURCE_DIR}/generated/arm/arm.urdf" "${SOURCE_DIR}/generated/arm/layout.yaml" DESTINATION "${WORK_DIR}/inputs")
set(build "${WORK_DIR}/build")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/downstream" -B "${build}" -G Ninja
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release
    -DARM_URDF=${WORK_DIR}/inputs/arm.urdf -DARM_LAYOUT=${WORK_DIR}/inputs/layout.yaml
    -DCHECKED_IN_DIR=${SOURCE_DIR}/generated/arm)
run(${CMAKE_COMMAND} --build "${build}")
if(NOT LAST_OUTPUT MATCHES "proxgen: generating arm_built")
  message(FATAL_ERROR "the first build did not run the generator:\n${LAST_OUTPUT}")
endif()
run("${build}/downstream")
message(STATUS "${LAST_OUTPUT}")

# Nothing changed: no regeneration.
run(${CMAKE_COMMAND} --build "${build}")
if(LAST_OUTPUT MATCHES "proxgen: generating")
  message(FATAL_ERROR "a no-op rebuild regenerated the solver:\n${LAST_OUTPUT}")
endif()

# The layout changes: the build must regenerate, and the solver must follow.
file(READ "${WORK_DIR}/inputs/layout.yaml" layout)
string(REGEX REPLACE "\nmu:[^\n]*" "\nmu: 2500" layout "${layout}")
if(NOT layout MATCHES "\nmu: 2500")
  string(APPEND layout "\nmu: 2500\n")
endif()
file(WRITE "${WORK_DIR}/inputs/layout.yaml" "${layout}")
run(${CMAKE_COMMAND} --build "${build}")
if(NOT LAST_OUTPUT MATCHES "proxgen: generating arm_built")
  message(FATAL_ERROR "changing the layout did not regenerate the solver:\n${LAST_OUTPUT}")
endif()
run("${build}/downstream" 2500)
message(STATUS "${LAST_OUTPUT}")
