# proxgen_add_solver(<target> URDF <file> LAYOUT <file>
#                    [SCALAR double|float] [NAME <namespace>] [OUTPUT_DIR <dir>]
#                    [FUNCTIONS <name>... | all] [BATCH <W>])
#
# Generates a solver for one robot and layout at build time and makes it a
# static library target <target> to link. The solver is regenerated whenever
# the URDF, the layout or the proxgen executable changes. NAME defaults to
# <target>; the generated header is <NAME>.hpp, and <NAME>_c.h the C interface
# (its definitions are compiled into <target> too: a C program links <target>). FUNCTIONS (a list: constrained_aba,
# prox_pv, inverse_dynamics, nonlinear_effects, mass_matrix, mass_matrix_inverse,
# ... or all) picks the functions the solver holds, as `generate --functions`
# (default: the layout's `functions:`, else the two solvers); proxgen checks the names.
# BATCH <W> (2, 4, 8 or 16) adds the batched solvers, W states per call
# (`generate --batch W`, docs/batch.md): <NAME>_batch.hpp and its source in the
# same library.
#
# Needs PROXGEN_EXECUTABLE (path or generator expression), PROXGEN_EXECUTABLE_DEPENDS
# (what the generation step depends on for "proxgen changed") and
# PROXGEN_RUNTIME_INCLUDE_DIR; proxgenConfig.cmake and the in-tree build set them.
# proxgen_solver_compile_options(<out_var> [CHECKED]): the compile options of
# every generated solver: what proxgen_add_solver gives one, and with CHECKED
# what the project's own compiles of generated code add to them (the
# generated-solver tests in tests/generated, `proxgen verify`, through a list
# baked in at configure time, and tests/generated/measure.sh, through
# <build>/generator/solver_compile_options.txt), so what is tested is what users
# build.
# Always: with GCC, no basic-block vectoriser: it packs unrelated scalar
# products of the straight-line code into vectors and pays more in shuffles than
# it saves; without it the solvers run 2-6 % fewer instructions in 3-9 % less
# time and the largest compile faster (with the column loops: 34 -> 20 s at -O2;
# docs/benchmarks.md, "Emitted code"). Loops (the constraint columns) are still
# vectorised.
# CHECKED adds: -O2 (the level of every measured figure; a user's build keeps
# its build type's level), no exceptions and no RTTI (the header contract: a
# solver needs neither), and warnings as errors (generated code must be
# warning-free under -Wall -Wextra -Wpedantic).
function(proxgen_solver_compile_options out)
  cmake_parse_arguments(PARSE_ARGV 1 PSCO "CHECKED" "" "")
  set(options "")
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    list(APPEND options -fno-tree-slp-vectorize)
  endif()
  if(PSCO_CHECKED)
    list(APPEND options -O2 -fno-exceptions -fno-rtti -Wall -Wextra -Wpedantic -Werror)
  endif()
  set(${out} "${options}" PARENT_SCOPE)
endfunction()

# SCALAR, NAME and OUTPUT_DIR of a generated-solver target, defaulted and
# checked alike for proxgen_add_solver and proxgen_add_python_module: a macro,
# so <prefix>_SCALAR, <prefix>_NAME, <prefix>_OUTPUT_DIR and `functions` land in the caller.
macro(_proxgen_solver_defaults where prefix target)
  if(NOT ${prefix}_SCALAR)
    set(${prefix}_SCALAR double)
  endif()
  if(NOT ${prefix}_SCALAR MATCHES "^(double|float)$")
    message(FATAL_ERROR "${where}: SCALAR must be double or float, not '${${prefix}_SCALAR}'")
  endif()
  if(NOT ${prefix}_NAME)
    set(${prefix}_NAME ${target})
  endif()
  if(NOT ${prefix}_NAME MATCHES "^[A-Za-z][A-Za-z0-9_]*$")
    message(FATAL_ERROR "${where}: NAME '${${prefix}_NAME}' is not a C++ identifier")
  endif()
  if(NOT ${prefix}_OUTPUT_DIR)
    set(${prefix}_OUTPUT_DIR "${CMAKE_CURRENT_BINARY_DIR}/proxgen/${target}")
  endif()
  # FUNCTIONS a b ... -> `functions` = --functions a,b (empty when not given).
  set(functions "")
  if(DEFINED ${prefix}_FUNCTIONS OR "FUNCTIONS" IN_LIST ${prefix}_KEYWORDS_MISSING_VALUES)
    if(NOT ${prefix}_FUNCTIONS)
      message(FATAL_ERROR "${where}: FUNCTIONS needs at least one function name")
    endif()
    list(JOIN ${prefix}_FUNCTIONS "," joined)
    set(functions --functions "${joined}")
  endif()
endmacro()

function(proxgen_add_solver target)
  cmake_parse_arguments(PARSE_ARGV 1 PAS "" "URDF;LAYOUT;SCALAR;NAME;OUTPUT_DIR;BATCH" "FUNCTIONS")
  if(PAS_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "proxgen_add_solver(${target}): unknown arguments: ${PAS_UNPARSED_ARGUMENTS}")
  endif()
  foreach(required URDF LAYOUT)
    if(NOT PAS_${required})
      message(FATAL_ERROR "proxgen_add_solver(${target}): ${required} <file> is required")
    endif()
  endforeach()
  _proxgen_solver_defaults("proxgen_add_solver(${target})" PAS ${target})
  get_filename_component(urdf "${PAS_URDF}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  get_filename_component(layout "${PAS_LAYOUT}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  foreach(input "${urdf}" "${layout}")
    if(NOT EXISTS "${input}")
      message(FATAL_ERROR "proxgen_add_solver(${target}): ${input} does not exist")
    endif()
  endforeach()
  if(NOT PROXGEN_EXECUTABLE OR NOT PROXGEN_RUNTIME_INCLUDE_DIR)
    message(FATAL_ERROR "proxgen_add_solver: use find_package(proxgen) or the proxgen source tree first")
  endif()

  set(hpp "${PAS_OUTPUT_DIR}/${PAS_NAME}.hpp")
  set(cpp "${PAS_OUTPUT_DIR}/${PAS_NAME}.cpp")
  # The C interface (NAME_c.h, NAME_c.cpp; docs/design.md "The C interface"):
  # compiled into the same library, so C code includes NAME_c.h and links <target>.
  set(c_h "${PAS_OUTPUT_DIR}/${PAS_NAME}_c.h")
  set(c_cpp "${PAS_OUTPUT_DIR}/${PAS_NAME}_c.cpp")
  set(batch "")
  set(batch_files "")
  if(DEFINED PAS_BATCH OR "BATCH" IN_LIST PAS_KEYWORDS_MISSING_VALUES)
    if(NOT PAS_BATCH MATCHES "^(2|4|8|16)$")
      message(FATAL_ERROR "proxgen_add_solver(${target}): BATCH must be 2, 4, 8 or 16, not '${PAS_BATCH}'")
    endif()
    set(batch --batch ${PAS_BATCH})
    set(batch_files "${PAS_OUTPUT_DIR}/${PAS_NAME}_batch.hpp" "${PAS_OUTPUT_DIR}/${PAS_NAME}_batch.cpp")
  endif()
  add_custom_command(
    OUTPUT "${hpp}" "${cpp}" "${c_h}" "${c_cpp}" ${batch_files}
    COMMAND "${PROXGEN_EXECUTABLE}" generate "${urdf}" --layout "${layout}" --out "${PAS_OUTPUT_DIR}"
            --name "${PAS_NAME}" --scalar "${PAS_SCALAR}" ${functions} ${batch}
    DEPENDS "${urdf}" "${layout}" ${PROXGEN_EXECUTABLE_DEPENDS}
    COMMENT "proxgen: generating ${PAS_NAME} (${PAS_SCALAR}) from ${urdf}"
    VERBATIM)
  add_library(${target} STATIC "${cpp}" "${hpp}" "${c_cpp}" "${c_h}" ${batch_files})
  if(batch_files AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # GCC notes that passing 32-byte vectors by value changed ABI in GCC 4.6: a
    # note on the lanes (proxgen/lanes.hpp) between this file's own functions.
    set_source_files_properties("${PAS_OUTPUT_DIR}/${PAS_NAME}_batch.cpp" TARGET_DIRECTORY ${target}
                                PROPERTIES COMPILE_OPTIONS -Wno-psabi)
  endif()
  target_include_directories(${target} PUBLIC "${PAS_OUTPUT_DIR}" "${PROXGEN_RUNTIME_INCLUDE_DIR}")
  target_compile_features(${target} PUBLIC cxx_std_17)
  proxgen_solver_compile_options(options)
  target_compile_options(${target} PRIVATE ${options})
  # A project that sets no build type gets no -O flag from CMake at all, and a
  # solver compiled at -O0 is more than twice as slow as at -O2, the level of
  # docs/benchmarks.md (README, "Install and packaging"). With an empty build
  # type, and no -O in the project's CMAKE_CXX_FLAGS, the solver alone gets
  # -O2. A chosen build type (Debug included: -O0 was asked for) or -O level is
  # never overridden, and target_compile_options(<target> PRIVATE -O...) after
  # this call comes later on the command line and wins.
  if(NOT CMAKE_CXX_FLAGS MATCHES "(^| )-O")
    target_compile_options(${target} PRIVATE $<$<STREQUAL:$<CONFIG>,>:-O2>)
  endif()
  set_target_properties(${target} PROPERTIES PROXGEN_HEADER "${hpp}" PROXGEN_SOURCE "${cpp}")
  if(batch_files)
    list(GET batch_files 0 batch_hpp)
    list(GET batch_files 1 batch_cpp)
    set_target_properties(${target} PROPERTIES PROXGEN_BATCH_HEADER "${batch_hpp}" PROXGEN_BATCH_SOURCE "${batch_cpp}")
  endif()
endfunction()
