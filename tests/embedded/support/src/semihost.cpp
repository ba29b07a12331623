// ARM semihosting calls: r0 = operation, r1 = parameter, then "bkpt 0xAB" (Thumb / M-profile).
#include "fw/semihost.hpp"

namespace {

constexpr int kSysWrite0 = 0x04;
constexpr int kSysExitExtended = 0x20;
constexpr std::uint32_t kAdpStoppedApplicationExit = 0x20026;

inline int semihost_call(int op, const void* arg) noexcept {
  register int r0 __asm__("r0") = op;
  register const void* r1 __asm__("r1") = arg;
  __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

}  // namespace

namespace fw {

void write0(const char* s) noexcept { semihost_call(kSysWrite0, s); }

void exit(int code) noexcept {
  // Parameter block of SYS_EXIT_EXTENDED: {reason, subcode}. qemu exits with `subcode`.
  const std::uint32_t block[2] = {kAdpStoppedApplicationExit, static_cast<std::uint32_t>(code)};
  semihost_call(kSysExitExtended, block);
  for (;;) __asm volatile("wfi");  // not reached under qemu
}

}  // namespace fw

// Markers for count_insns.py: real, distinct, never inlined or merged functions whose entry the
// instruction trace shows by name.
extern "C" __attribute__((noinline, noipa, used)) void fw_trace_begin() noexcept {
  __asm volatile("nop  @ fw_trace_begin" ::: "memory");
}
extern "C" __attribute__((noinline, noipa, used)) void fw_trace_end() noexcept {
  __asm volatile("nop  @ fw_trace_end\n nop" ::: "memory");
}
