# Shared part of the proxgen bare-metal toolchain files (GNU Arm Embedded, arm-none-eabi-gcc >= 10).
# Not used directly: include it from a per-CPU toolchain file that first sets
#   PROXGEN_EMBEDDED_CPU_FLAGS   e.g. "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb"
#   PROXGEN_EMBEDDED_CPU         e.g. cortex-m7   (checked by proxgen_add_firmware)
#   PROXGEN_EMBEDDED_MACHINE     default qemu machine for firmware, e.g. mps2-an500
#   PROXGEN_EMBEDDED_SCALAR      the solver scalar this FPU runs in hardware: double or float
#
# The compilers are looked up on PATH as arm-none-eabi-*; set ARM_NONE_EABI_TOOLCHAIN_DIR
# (cache/env) to the folder holding them to use another installation.

set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
# No OS, no start files: a test *executable* would not link, so CMake's compiler checks
# build a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

if(NOT ARM_NONE_EABI_TOOLCHAIN_DIR AND DEFINED ENV{ARM_NONE_EABI_TOOLCHAIN_DIR})
  set(ARM_NONE_EABI_TOOLCHAIN_DIR "$ENV{ARM_NONE_EABI_TOOLCHAIN_DIR}")
endif()
if(ARM_NONE_EABI_TOOLCHAIN_DIR)
  set(_proxgen_tc_prefix "${ARM_NONE_EABI_TOOLCHAIN_DIR}/arm-none-eabi-")
else()
  set(_proxgen_tc_prefix "arm-none-eabi-")
endif()

set(CMAKE_C_COMPILER   "${_proxgen_tc_prefix}gcc")
set(CMAKE_CXX_COMPILER "${_proxgen_tc_prefix}g++")
set(CMAKE_ASM_COMPILER "${_proxgen_tc_prefix}gcc")
find_program(PROXGEN_ARM_SIZE    NAMES "${_proxgen_tc_prefix}size" arm-none-eabi-size)
find_program(PROXGEN_ARM_OBJDUMP NAMES "${_proxgen_tc_prefix}objdump" arm-none-eabi-objdump)
find_program(PROXGEN_ARM_NM      NAMES "${_proxgen_tc_prefix}nm" arm-none-eabi-nm)

# Flags every translation unit gets. -fstack-usage writes a .su file (frame size per function)
# beside each object file. --specs=nano.specs selects newlib-nano (headers and libraries).
set(_proxgen_common_flags
    "${PROXGEN_EMBEDDED_CPU_FLAGS} -ffunction-sections -fdata-sections -fstack-usage --specs=nano.specs")

set(PROXGEN_EMBEDDED_C_FLAGS   "${_proxgen_common_flags}")
set(PROXGEN_EMBEDDED_CXX_FLAGS "${_proxgen_common_flags} -fno-exceptions -fno-rtti -fno-threadsafe-statics")
set(PROXGEN_EMBEDDED_ASM_FLAGS "${PROXGEN_EMBEDDED_CPU_FLAGS}")
# Note: CMake ignores *_FLAGS_INIT when CMAKE_<LANG>_FLAGS is given on the command line
# (-DCMAKE_CXX_FLAGS=...). tests/embedded/ProxgenFirmware.cmake detects that and puts the
# PROXGEN_EMBEDDED_<LANG>_FLAGS back in front.
set(CMAKE_C_FLAGS_INIT   "${PROXGEN_EMBEDDED_C_FLAGS}")
set(CMAKE_CXX_FLAGS_INIT "${PROXGEN_EMBEDDED_CXX_FLAGS}")
set(CMAKE_ASM_FLAGS_INIT "${PROXGEN_EMBEDDED_ASM_FLAGS}")

# Our own vector table and reset handler (no crt0, no crti/crtbegin): -nostartfiles.
# Unused sections are dropped: --gc-sections (pairs with -ffunction/-fdata-sections).
# --specs=nano.specs and the CPU flags reach the link through CMAKE_<LANG>_FLAGS, which CMake
# puts on the link line too; giving --specs twice is a gcc error ("attempt to rename spec").
set(CMAKE_EXE_LINKER_FLAGS_INIT "-nostartfiles -Wl,--gc-sections")

set(CMAKE_EXECUTABLE_SUFFIX_C   ".elf")
set(CMAKE_EXECUTABLE_SUFFIX_CXX ".elf")
set(CMAKE_EXECUTABLE_SUFFIX_ASM ".elf")

# Never pick up host libraries or headers; host programs (python3, qemu) are fine.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Let try_compile() projects see the CPU description too.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES
     PROXGEN_EMBEDDED_CPU_FLAGS PROXGEN_EMBEDDED_CPU PROXGEN_EMBEDDED_MACHINE
     PROXGEN_EMBEDDED_SCALAR PROXGEN_EMBEDDED_C_FLAGS PROXGEN_EMBEDDED_CXX_FLAGS
     PROXGEN_EMBEDDED_ASM_FLAGS ARM_NONE_EABI_TOOLCHAIN_DIR)
