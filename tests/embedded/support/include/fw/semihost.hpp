// ARM semihosting (the "bkpt 0xAB" convention of Cortex-M) for firmware run under qemu with
// `-semihosting-config enable=on,target=native`, or under a debug probe that implements it.
// On a board with no debugger attached, a semihosting call is a HardFault: test firmware only.
#pragma once
#include <cstdint>

namespace fw {

// SYS_WRITE0 (0x04): writes a NUL-terminated string to the host's console (qemu: its stdout).
void write0(const char* s) noexcept;

// SYS_EXIT_EXTENDED (0x20) with reason ADP_Stopped_ApplicationExit (0x20026) and `code`:
// qemu exits with status `code` (0..255 is what a shell sees).
[[noreturn]] void exit(int code) noexcept;

// Exit codes used by the support code itself (tests use 0 = pass, 1 = fail).
inline constexpr int exit_fault = 101;   // HardFault or another unexpected exception
inline constexpr int exit_abort = 102;   // abort(), std::terminate, pure virtual call
inline constexpr int exit_assert = 103;  // a failed assert()

}  // namespace fw
