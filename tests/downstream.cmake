# ctest driver for the downstream project: install proxgen into a prefix,
# configure and build a user project against it (proxgen_add_solver,
# proxgen::runtime, proxgen::core; the solver with BATCH 4, its batched forms
# checked against its scalar ones by main.cpp), run it, then change the layout
# and check that the build regenerates the solver and its batched source
# (Settings::mu follows it). Then the
# optimisation level a solver gets with and without a build type, and the
# pkg-config files.
# Inputs: -DBUILD_DIR= (proxgen build tree) -DSOURCE_DIR= (proxgen sources) -DWORK_DIR= (scratch)
cmake_minimum_required(VERSION 3.22)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(LAST_OUTPUT "${out}${err}" PARENT_SCOPE)
endfunction()

# The compile command of the one source of <build>/compile_commands.json whose
# path ends with <tail>, in <out>.
function(compile_command build tail out)
  file(READ "${build}/compile_commands.json" json)
  string(JSON n LENGTH "${json}")
  math(EXPR last "${n} - 1")
  foreach(k RANGE ${last})
    string(JSON file GET "${json}" ${k} file)
    if(file MATCHES "${tail}$")
      string(JSON command GET "${json}" ${k} command)
      set(${out} "${command}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
  message(FATAL_ERROR "no ${tail} in ${build}/compile_commands.json")
endfunction()

# The -O options of a compile command, in order ("" when it has none).
function(optimisation_flags command out)
  string(REGEX MATCHALL "(^| )-O[^ ]*" flags "${command}")
  string(REPLACE " " "" flags "${flags}")
  set(${out} "${flags}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
file(COPY "${SOURCE_DIR}/generated/arm/arm.urdf" "${SOURCE_DIR}/generated/arm/layout.yaml" DESTINATION "${WORK_DIR}/inputs")
set(build "${WORK_DIR}/build")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/downstream" -B "${build}" -G Ninja
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release
    -DARM_URDF=${WORK_DIR}/inputs/arm.urdf -DARM_LAYOUT=${WORK_DIR}/inputs/layout.yaml
    -DCHECKED_IN_DIR=${SOURCE_DIR}/generated/arm -DCMAKE_EXPORT_COMPILE_COMMANDS=ON
    "-DCMAKE_CXX_FLAGS=")  # not the environment's CXXFLAGS: the -O flags below are then known
# A chosen build type keeps its level: Release's -O3, no -O2 from proxgen after it.
compile_command("${build}" "/arm_built.cpp" solver_command)
optimisation_flags("${solver_command}" solver_levels)
if(NOT solver_levels STREQUAL "-O3")
  message(FATAL_ERROR "with CMAKE_BUILD_TYPE=Release the solver's -O flags are '${solver_levels}', not Release's -O3:\n${solver_command}")
endif()
run(${CMAKE_COMMAND} --build "${build}")
if(NOT LAST_OUTPUT MATCHES "proxgen: generating arm_built")
  message(FATAL_ERROR "the first build did not run the generator:\n${LAST_OUTPUT}")
endif()
run("${build}/downstream")
message(STATUS "${LAST_OUTPUT}")
run("${build}/cross_check" "${WORK_DIR}/inputs/arm.urdf" "${WORK_DIR}/inputs/layout.yaml")
message(STATUS "${LAST_OUTPUT}")

# Nothing changed: no regeneration.
run(${CMAKE_COMMAND} --build "${build}")
if(LAST_OUTPUT MATCHES "proxgen: generating")
  message(FATAL_ERROR "a no-op rebuild regenerated the solver:\n${LAST_OUTPUT}")
endif()

# The layout changes: the build must regenerate, and the solver must follow.
# The batched source too (BATCH 4): its banner holds the layout's hash.
set(batch_cpp "${build}/proxgen/arm_solver/arm_built_batch.cpp")  # proxgen_add_solver's default OUTPUT_DIR
file(READ "${batch_cpp}" batch_before)
if(NOT batch_before MATCHES "--batch 4")
  message(FATAL_ERROR "${batch_cpp} does not say it was generated with --batch 4")
endif()
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
file(READ "${batch_cpp}" batch_after)
if(batch_after STREQUAL batch_before)
  message(FATAL_ERROR "changing the layout did not regenerate ${batch_cpp}")
endif()
run("${build}/downstream" 2500)
message(STATUS "${LAST_OUTPUT}")
run("${build}/cross_check" "${WORK_DIR}/inputs/arm.urdf" "${WORK_DIR}/inputs/layout.yaml")
message(STATUS "${LAST_OUTPUT}")

# No build type: CMake adds no -O flag, proxgen_add_solver gives the solver -O2
# and nothing else (the user's own targets stay as the user left them). With a
# level in CMAKE_CXX_FLAGS the user chose, and proxgen adds none. Configuring
# is enough: compile_commands.json holds the commands.
foreach(variant "none|" "Os|-Os")
  string(REPLACE "|" ";" variant "${variant}")
  list(GET variant 0 tag)
  list(LENGTH variant parts)
  set(flags "")
  if(parts GREATER 1)
    list(GET variant 1 flags)
  endif()
  set(notype "${WORK_DIR}/build-notype-${tag}")
  run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/downstream" -B "${notype}" -G Ninja
      -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE= "-DCMAKE_CXX_FLAGS=${flags}" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON
      -DARM_URDF=${WORK_DIR}/inputs/arm.urdf -DARM_LAYOUT=${WORK_DIR}/inputs/layout.yaml
      -DCHECKED_IN_DIR=${SOURCE_DIR}/generated/arm)
  compile_command("${notype}" "/arm_built.cpp" solver_command)
  compile_command("${notype}" "/main.cpp" user_command)
  optimisation_flags("${solver_command}" solver_levels)
  optimisation_flags("${user_command}" user_levels)
  if(flags STREQUAL "")
    set(expected_solver "-O2")
  else()
    set(expected_solver "${flags}")
  endif()
  if(NOT solver_levels STREQUAL expected_solver OR NOT user_levels STREQUAL flags)
    message(FATAL_ERROR "no build type, CMAKE_CXX_FLAGS='${flags}': the solver's -O flags are '${solver_levels}' "
                        "(expected '${expected_solver}'), the user's '${user_levels}' (expected '${flags}'):\n"
                        "${solver_command}\n${user_command}")
  endif()
  message(STATUS "no build type, CMAKE_CXX_FLAGS='${flags}': solver ${solver_levels}, user's target '${user_levels}'")
endforeach()

# pkg-config: proxgen.pc gives the runtime's folder of this prefix, and is all a
# generated solver needs to compile; proxgen-core.pc compiles and links a
# program of the generic library. Relocatable: the prefix is not the one the
# build was configured with.
find_program(PKG_CONFIG_EXECUTABLE NAMES pkg-config pkgconf REQUIRED)
file(GLOB_RECURSE pc_files "${prefix}/*/proxgen.pc")
list(LENGTH pc_files pc_count)
if(NOT pc_count EQUAL 1)
  message(FATAL_ERROR "expected one proxgen.pc under ${prefix}, found: ${pc_files}")
endif()
get_filename_component(pc_dir "${pc_files}" DIRECTORY)
set(ENV{PKG_CONFIG_PATH} "${pc_dir}")
run(${PKG_CONFIG_EXECUTABLE} --cflags proxgen)
string(STRIP "${LAST_OUTPUT}" cflags)
if(NOT cflags MATCHES "^-I([^ ]+)$")
  message(FATAL_ERROR "pkg-config --cflags proxgen gave '${cflags}', not one -I folder")
endif()
file(REAL_PATH "${CMAKE_MATCH_1}" pc_include)
file(REAL_PATH "${prefix}/include" prefix_include)
if(NOT pc_include STREQUAL prefix_include OR NOT EXISTS "${pc_include}/proxgen/runtime.hpp")
  message(FATAL_ERROR "pkg-config --cflags proxgen gave ${pc_include}, not ${prefix_include} (which holds proxgen/runtime.hpp)")
endif()
load_cache("${BUILD_DIR}" READ_WITH_PREFIX PROXGEN_ CMAKE_CXX_COMPILER)
run(${PROXGEN_CMAKE_CXX_COMPILER} -std=c++17 ${cflags} -I${SOURCE_DIR}/generated/arm -c
    ${SOURCE_DIR}/generated/arm/arm.cpp -o ${WORK_DIR}/arm_pkgconfig.o)
run(${PKG_CONFIG_EXECUTABLE} --cflags --libs proxgen-core)
string(STRIP "${LAST_OUTPUT}" core_flags)
separate_arguments(core_flags UNIX_COMMAND "${core_flags}")
file(WRITE "${WORK_DIR}/core_pkgconfig.cpp" [=[
#include <cstdio>
#include "model/layout.hpp"
int main(int, char** argv) {
  const proxgen::System sys = proxgen::loadSystem(argv[1], argv[2]);
  std::printf("pkg-config proxgen-core: nv = %d, nc = %d\n", sys.model.nv, sys.nc);
  return sys.model.nv > 0 ? 0 : 1;
}
]=])
run(${PROXGEN_CMAKE_CXX_COMPILER} -std=c++17 "${WORK_DIR}/core_pkgconfig.cpp" -o "${WORK_DIR}/core_pkgconfig" ${core_flags})
run("${WORK_DIR}/core_pkgconfig" "${WORK_DIR}/inputs/arm.urdf" "${WORK_DIR}/inputs/layout.yaml")
message(STATUS "${LAST_OUTPUT}")
