// Run-time stack measurement. The reset handler fills the free RAM between .bss and the stack
// pointer with a pattern before main(); the high-water mark is the deepest word overwritten.
#pragma once
#include <cstddef>

namespace fw {

// Bytes of stack used so far (the deepest point reached since reset, including the frames of
// the start-up code). Scans memory: call it at the end of a test, not in a hot loop.
std::size_t stack_high_water() noexcept;

// Bytes available between the end of .bss and the top of RAM.
std::size_t stack_capacity() noexcept;

// The CPU this firmware was built for, e.g. "cortex-m7" (from the toolchain file).
const char* cpu_name() noexcept;

}  // namespace fw
