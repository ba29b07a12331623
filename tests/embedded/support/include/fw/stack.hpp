// Run-time stack measurement. The reset handler fills the stack budget (the top STACK_SIZE
// bytes of RAM, see proxgen_add_firmware) below the stack pointer with a pattern before main();
// the high-water mark is the deepest word overwritten.
#pragma once
#include <cstddef>

namespace fw {

// Bytes of stack used so far (the deepest point reached since reset, including the frames of
// the start-up code). Scans memory: call it at the end of a test, not in a hot loop.
// Saturates at stack_budget(): a result equal to the budget means the budget was exceeded.
std::size_t stack_high_water() noexcept;

// Bytes painted for the measurement: min(STACK_SIZE, stack_capacity()).
std::size_t stack_budget() noexcept;

// Bytes available between the end of .bss and the top of RAM.
std::size_t stack_capacity() noexcept;

// Prints "stack high water: N bytes (budget B, free RAM C)" and, when the
// budget was reached, "FAILED: stack budget exceeded"; false then. Every test
// firmware ends with it.
bool report_stack() noexcept;

// The CPU this firmware was built for, e.g. "cortex-m7" (from the toolchain file).
const char* cpu_name() noexcept;

}  // namespace fw
