# Toolchain file: ARM Cortex-M4F, single-precision FPU (FPv4-SP-D16), hard-float ABI.
# double arithmetic is software-emulated (__aeabi_d*): generate solvers with --scalar float.
# qemu target: mps2-an386.
#   cmake -G Ninja -S tests/embedded -B build-m4f \
#         -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/arm-none-eabi-cortex-m4f.cmake
set(PROXGEN_EMBEDDED_CPU cortex-m4)
set(PROXGEN_EMBEDDED_CPU_FLAGS "-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard -mthumb")
set(PROXGEN_EMBEDDED_MACHINE mps2-an386)
set(PROXGEN_EMBEDDED_SCALAR float)
include("${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake")
