# proxgen_add_firmware(): bare-metal test firmware for qemu's MPS2 boards.
#
# Include this file from a CMake project configured with one of the toolchain files in
# cmake/toolchains/ (arm-none-eabi-cortex-m7.cmake or arm-none-eabi-cortex-m4f.cmake).
#
#   proxgen_add_firmware(<name>
#       SOURCES file.cpp...            # your main() and everything it needs, e.g. a generated
#                                      # solver NAME.cpp and a generated test-vector .cpp
#       [INCLUDE_DIRS dir...]          # e.g. the solver's folder and the header-only runtime
#       [MACHINE mps2-an500|mps2-an386]# default: the toolchain's (M7 -> an500, M4F -> an386)
#       [COMPILE_DEFINITIONS def...] [COMPILE_OPTIONS opt...] [LINK_LIBRARIES lib...]
#       [CXX_STANDARD 17]              # default 17
#       [STACK_SIZE bytes]             # least free RAM above .bss, checked at link; default 131072
#       [TIMEOUT seconds]              # qemu run time limit of the test; default 60
#       [STACK_ROOTS name...]          # extra roots for the worst-stack report, e.g. the solver
#                                      # entry points "arm::constrained_aba" "arm::prox_pv"
#       [NO_SOFT_DOUBLE]               # fail the build if double-precision soft-float helpers
#                                      # (__aeabi_dadd, ...) are linked: for float solvers on M4F
#       [NO_TEST] [EXCLUDE_FROM_ALL])
#
# Produces <name>.elf, <name>.map, <name>.size.txt (arm-none-eabi-size), <name>.stack.txt
# (worst stack path, tests/embedded/stack_report.py), .su/.ci files in CMakeFiles/<name>.dir/,
# and, unless NO_TEST, a CTest test <name> that runs the ELF under qemu (run-qemu.sh) and
# passes when the firmware exits 0.
#
# Every firmware gets the support code compiled in: vector table and reset handler
# (support/src/startup.cpp), semihosting (semihost.cpp), printf-free formatting (format.cpp)
# and newlib stubs (syscalls.cpp); headers under support/include/fw/. The firmware provides
# main(); its return value becomes qemu's exit status.
include_guard(GLOBAL)

set(PROXGEN_FIRMWARE_DIR "${CMAKE_CURRENT_LIST_DIR}" CACHE INTERNAL "tests/embedded")

if(NOT DEFINED PROXGEN_EMBEDDED_CPU)
  message(FATAL_ERROR
    "ProxgenFirmware.cmake needs a proxgen embedded toolchain: configure with "
    "-DCMAKE_TOOLCHAIN_FILE=<repo>/cmake/toolchains/arm-none-eabi-cortex-m7.cmake (or -m4f)")
endif()

# -DCMAKE_CXX_FLAGS=... on the command line replaces the toolchain's CMAKE_CXX_FLAGS_INIT, and
# with it the CPU/FPU flags: put them back in front (for targets of this directory and below).
foreach(_lang C CXX ASM)
  if(DEFINED CMAKE_${_lang}_COMPILER_LOADED AND DEFINED PROXGEN_EMBEDDED_${_lang}_FLAGS)
    if(NOT " ${CMAKE_${_lang}_FLAGS} " MATCHES " -mcpu=")
      if(NOT _lang STREQUAL "ASM" AND " ${CMAKE_${_lang}_FLAGS} " MATCHES " --specs=")
        message(FATAL_ERROR "CMAKE_${_lang}_FLAGS has --specs but no -mcpu: it replaced the "
                            "toolchain's flags; add '${PROXGEN_EMBEDDED_CPU_FLAGS}' to it")
      endif()
      message(STATUS "proxgen: CMAKE_${_lang}_FLAGS lacks the toolchain's flags, prepending them")
      set(CMAKE_${_lang}_FLAGS "${PROXGEN_EMBEDDED_${_lang}_FLAGS} ${CMAKE_${_lang}_FLAGS}")
    endif()
  endif()
endforeach()

find_package(Python3 COMPONENTS Interpreter QUIET)
include(CheckCXXCompilerFlag)
check_cxx_compiler_flag("-fcallgraph-info=su" PROXGEN_HAVE_CALLGRAPH_INFO)

set(_PROXGEN_FW_SUPPORT_SOURCES
    "${PROXGEN_FIRMWARE_DIR}/support/src/startup.cpp"
    "${PROXGEN_FIRMWARE_DIR}/support/src/semihost.cpp"
    "${PROXGEN_FIRMWARE_DIR}/support/src/format.cpp"
    "${PROXGEN_FIRMWARE_DIR}/support/src/syscalls.cpp")

# machine -> CPU it needs (as set by the toolchain file)
set(_PROXGEN_FW_CPU_mps2-an500 cortex-m7)
set(_PROXGEN_FW_CPU_mps2-an386 cortex-m4)

function(proxgen_add_firmware name)
  set(options NO_SOFT_DOUBLE NO_TEST EXCLUDE_FROM_ALL)
  set(one_value MACHINE STACK_SIZE TIMEOUT CXX_STANDARD)
  set(multi_value SOURCES INCLUDE_DIRS COMPILE_DEFINITIONS COMPILE_OPTIONS LINK_LIBRARIES
                  STACK_ROOTS)
  cmake_parse_arguments(FW "${options}" "${one_value}" "${multi_value}" ${ARGN})
  if(FW_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "proxgen_add_firmware(${name}): unknown arguments ${FW_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT FW_SOURCES)
    message(FATAL_ERROR "proxgen_add_firmware(${name}): SOURCES is required")
  endif()
  if(NOT FW_MACHINE)
    set(FW_MACHINE "${PROXGEN_EMBEDDED_MACHINE}")
  endif()
  if(NOT DEFINED _PROXGEN_FW_CPU_${FW_MACHINE})
    message(FATAL_ERROR "proxgen_add_firmware(${name}): unknown MACHINE '${FW_MACHINE}' "
                        "(known: mps2-an500, mps2-an386)")
  endif()
  if(NOT _PROXGEN_FW_CPU_${FW_MACHINE} STREQUAL PROXGEN_EMBEDDED_CPU)
    message(FATAL_ERROR "proxgen_add_firmware(${name}): MACHINE ${FW_MACHINE} is a "
                        "${_PROXGEN_FW_CPU_${FW_MACHINE}}, but this build's toolchain targets "
                        "${PROXGEN_EMBEDDED_CPU}: use the matching toolchain file")
  endif()
  if(NOT FW_STACK_SIZE)
    set(FW_STACK_SIZE 131072)
  endif()
  if(NOT FW_TIMEOUT)
    set(FW_TIMEOUT 60)
  endif()
  if(NOT FW_CXX_STANDARD)
    set(FW_CXX_STANDARD 17)
  endif()

  set(ld_dir "${PROXGEN_FIRMWARE_DIR}/ld")
  set(ld_script "${ld_dir}/${FW_MACHINE}.ld")

  set(exclude)
  if(FW_EXCLUDE_FROM_ALL)
    set(exclude EXCLUDE_FROM_ALL)
  endif()
  add_executable(${name} ${exclude} ${FW_SOURCES} ${_PROXGEN_FW_SUPPORT_SOURCES})
  set_target_properties(${name} PROPERTIES
    SUFFIX ".elf"
    CXX_STANDARD ${FW_CXX_STANDARD}
    CXX_STANDARD_REQUIRED ON
    CXX_EXTENSIONS OFF
    LINK_DEPENDS "${ld_script};${ld_dir}/sections.ld;${PROXGEN_FIRMWARE_DIR}/ProxgenFirmwarePost.cmake;${PROXGEN_FIRMWARE_DIR}/stack_report.py"
    PROXGEN_MACHINE "${FW_MACHINE}")
  target_include_directories(${name} PRIVATE ${FW_INCLUDE_DIRS}
                                             "${PROXGEN_FIRMWARE_DIR}/support/include")
  target_compile_definitions(${name} PRIVATE ${FW_COMPILE_DEFINITIONS})
  set_source_files_properties("${PROXGEN_FIRMWARE_DIR}/support/src/startup.cpp"
    TARGET_DIRECTORY ${name}
    PROPERTIES COMPILE_DEFINITIONS "PROXGEN_FW_CPU_NAME=\"${PROXGEN_EMBEDDED_CPU}\"")
  target_compile_options(${name} PRIVATE -Wall -Wextra ${FW_COMPILE_OPTIONS})
  if(PROXGEN_HAVE_CALLGRAPH_INFO)
    target_compile_options(${name} PRIVATE -fcallgraph-info=su)
  endif()
  target_link_options(${name} PRIVATE
    -nostartfiles -Wl,--gc-sections  # also in the toolchain's linker flags; repeated in case
                                     # CMAKE_EXE_LINKER_FLAGS was replaced on the command line
    "-L${ld_dir}" "-T${ld_script}"
    "-Wl,--defsym=__stack_size=${FW_STACK_SIZE}"
    "-Wl,-Map=$<TARGET_FILE_DIR:${name}>/${name}.map"
    "-Wl,--print-memory-usage")
  if(FW_LINK_LIBRARIES)
    target_link_libraries(${name} PRIVATE ${FW_LINK_LIBRARIES})
  endif()

  set(python "")
  if(Python3_Interpreter_FOUND)
    set(python "${Python3_EXECUTABLE}")
  endif()
  add_custom_command(TARGET ${name} POST_BUILD
    COMMAND "${CMAKE_COMMAND}"
            "-DELF=$<TARGET_FILE:${name}>"
            "-DNAME=${name}"
            "-DOUT_DIR=$<TARGET_FILE_DIR:${name}>"
            "-DOBJ_DIR=${CMAKE_CURRENT_BINARY_DIR}/CMakeFiles/${name}.dir"
            "-DSIZE=${PROXGEN_ARM_SIZE}"
            "-DNM=${PROXGEN_ARM_NM}"
            "-DOBJDUMP=${PROXGEN_ARM_OBJDUMP}"
            "-DPYTHON=${python}"
            "-DSTACK_SCRIPT=${PROXGEN_FIRMWARE_DIR}/stack_report.py"
            "-DNO_SOFT_DOUBLE=${FW_NO_SOFT_DOUBLE}"
            "-DSTACK_ROOTS=${FW_STACK_ROOTS}"
            -P "${PROXGEN_FIRMWARE_DIR}/ProxgenFirmwarePost.cmake"
    VERBATIM)

  if(NOT FW_NO_TEST)
    add_test(NAME ${name}
             COMMAND "${PROXGEN_FIRMWARE_DIR}/run-qemu.sh" "${FW_MACHINE}"
                     "$<TARGET_FILE:${name}>" "${FW_TIMEOUT}")
    set_tests_properties(${name} PROPERTIES TIMEOUT "${FW_TIMEOUT}0" LABELS "embedded;qemu")
  endif()
endfunction()

# proxgen_add_link_failure_test(<test> <target> <regex>): a CTest test that builds <target>
# (declared EXCLUDE_FROM_ALL) and passes only if the build output matches <regex>; used to prove
# that forbidden code (heap use) does not link.
function(proxgen_add_link_failure_test test target regex)
  add_test(NAME ${test}
           COMMAND "${CMAKE_COMMAND}" --build "${CMAKE_BINARY_DIR}" --target ${target})
  set_tests_properties(${test} PROPERTIES
    PASS_REGULAR_EXPRESSION "${regex}"
    RESOURCE_LOCK "proxgen_build_dir_${CMAKE_BINARY_DIR}"
    LABELS "embedded;link")
endfunction()
