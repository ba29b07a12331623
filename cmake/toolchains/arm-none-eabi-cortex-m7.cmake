# Toolchain file: ARM Cortex-M7 with the double-precision FPU (FPv5-D16), hard-float ABI.
# Runs double-precision solvers in hardware. qemu target: mps2-an500.
#   cmake -G Ninja -S tests/embedded -B build-m7 \
#         -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/arm-none-eabi-cortex-m7.cmake
set(PROXGEN_EMBEDDED_CPU cortex-m7)
set(PROXGEN_EMBEDDED_CPU_FLAGS "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb")
set(PROXGEN_EMBEDDED_MACHINE mps2-an500)
set(PROXGEN_EMBEDDED_SCALAR double)
include("${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake")
