# proxgen_add_python_module(<target> URDF <file> LAYOUT <file>
#                           [NAME <module>] [SCALAR double|float] [OUTPUT_DIR <dir>]
#                           [FUNCTIONS <name>... | all])
# proxgen_add_python_module(<target> CASES <cases.yaml> CASE <name> [NAME ...] ...)
#
# Generates a solver with `proxgen generate --python` at build time and builds
# the importable extension module <NAME> (NAME.prox_pv, NAME.constrained_aba and
# the library functions FUNCTIONS selects, as proxgen_add_solver's FUNCTIONS or
# the layout's `functions:`; docs/python.md) from NAME_python.cpp and NAME.cpp. NAME defaults to <target>
# and must be a C++ identifier (it is the namespace, the file stem and the
# Python module name). The module lands in the target's LIBRARY_OUTPUT_DIRECTORY
# (default: OUTPUT_DIR); put that folder on PYTHONPATH, or install the target.
#
# Needs pybind11 (find_package(pybind11 CONFIG) after finding Python3) and what
# proxgen_add_solver needs (PROXGEN_EXECUTABLE, PROXGEN_EXECUTABLE_DEPENDS,
# PROXGEN_RUNTIME_INCLUDE_DIR); PROXGEN_PYTHON_INCLUDE_DIR (where
# proxgen/python_module.hpp is) defaults to PROXGEN_RUNTIME_INCLUDE_DIR, as installed.
function(proxgen_add_python_module target)
  cmake_parse_arguments(PARSE_ARGV 1 PPM "" "URDF;LAYOUT;CASES;CASE;SCALAR;NAME;OUTPUT_DIR" "FUNCTIONS")
  set(where "proxgen_add_python_module(${target})")
  if(PPM_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "${where}: unknown arguments: ${PPM_UNPARSED_ARGUMENTS}")
  endif()
  if(PPM_CASES OR PPM_CASE)
    if(NOT PPM_CASES OR NOT PPM_CASE OR PPM_URDF OR PPM_LAYOUT)
      message(FATAL_ERROR "${where}: CASES and CASE go together, without URDF or LAYOUT")
    endif()
    set(inputs CASES)
  else()
    if(NOT PPM_URDF OR NOT PPM_LAYOUT)
      message(FATAL_ERROR "${where}: URDF <file> and LAYOUT <file> (or CASES and CASE) are required")
    endif()
    set(inputs URDF LAYOUT)
  endif()
  _proxgen_solver_defaults("${where}" PPM ${target})
  if(NOT COMMAND pybind11_add_module)
    message(FATAL_ERROR "${where}: needs pybind11: find_package(Python3 COMPONENTS Interpreter Development.Module) and find_package(pybind11 CONFIG) first")
  endif()
  if(NOT PROXGEN_EXECUTABLE OR NOT PROXGEN_RUNTIME_INCLUDE_DIR)
    message(FATAL_ERROR "${where}: use find_package(proxgen) or the proxgen source tree first")
  endif()
  set(include_dir "${PROXGEN_PYTHON_INCLUDE_DIR}")
  if(NOT include_dir)
    set(include_dir "${PROXGEN_RUNTIME_INCLUDE_DIR}")
  endif()

  set(files)
  foreach(input ${inputs})
    get_filename_component(file "${PPM_${input}}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    if(NOT EXISTS "${file}")
      message(FATAL_ERROR "${where}: ${file} does not exist")
    endif()
    set(abs_${input} "${file}")
    list(APPEND files "${file}")
  endforeach()
  if(PPM_CASES)
    set(robot_args --cases "${abs_CASES}" --case "${PPM_CASE}")
  else()
    set(robot_args "${abs_URDF}" --layout "${abs_LAYOUT}")
  endif()

  set(hpp "${PPM_OUTPUT_DIR}/${PPM_NAME}.hpp")
  set(cpp "${PPM_OUTPUT_DIR}/${PPM_NAME}.cpp")
  set(py "${PPM_OUTPUT_DIR}/${PPM_NAME}_python.cpp")
  # A cases file names its URDF inside; the generation also reruns when proxgen changes.
  add_custom_command(
    OUTPUT "${hpp}" "${cpp}" "${py}"
    COMMAND "${PROXGEN_EXECUTABLE}" generate ${robot_args} --out "${PPM_OUTPUT_DIR}"
            --name "${PPM_NAME}" --scalar "${PPM_SCALAR}" ${functions} --python
    DEPENDS ${files} ${PROXGEN_EXECUTABLE_DEPENDS}
    COMMENT "proxgen: generating the Python module ${PPM_NAME} (${PPM_SCALAR})"
    VERBATIM)
  pybind11_add_module(${target} MODULE NO_EXTRAS "${py}" "${cpp}" "${hpp}")
  target_include_directories(${target} PRIVATE "${PPM_OUTPUT_DIR}" "${PROXGEN_RUNTIME_INCLUDE_DIR}" "${include_dir}")
  target_compile_features(${target} PRIVATE cxx_std_17)
  proxgen_solver_compile_options(options)
  set_source_files_properties("${cpp}" PROPERTIES COMPILE_OPTIONS "${options}")
  set_target_properties(${target} PROPERTIES OUTPUT_NAME "${PPM_NAME}" LIBRARY_OUTPUT_DIRECTORY "${PPM_OUTPUT_DIR}"
                                             PROXGEN_HEADER "${hpp}" PROXGEN_SOURCE "${cpp}")
endfunction()
