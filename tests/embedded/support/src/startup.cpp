// Vector table, reset handler and fault handlers for Cortex-M3/M4/M7 firmware (no crt0).
//
// Reset_Handler: sets SP, enables the FPU (CPACR), copies .data, clears .bss, paints the
// stack budget for fw::stack_high_water(), runs C++ static constructors (__preinit_array,
// __init_array), calls main() and exits through semihosting with main's return value.
#include <cstddef>
#include <cstdint>

#include "fw/io.hpp"
#include "fw/stack.hpp"

#ifndef PROXGEN_FW_CPU_NAME
#define PROXGEN_FW_CPU_NAME "unknown"
#endif

extern "C" {
// From the linker script (sections.ld).
extern std::uint32_t __stack_top[];
extern std::uint32_t __stack_limit[];
extern std::uint32_t __stack_paint_bottom[];
extern std::uint32_t _sidata[];
extern std::uint32_t _sdata[];
extern std::uint32_t _edata[];
extern std::uint32_t _sbss[];
extern std::uint32_t _ebss[];
extern void (*__preinit_array_start[])();
extern void (*__preinit_array_end[])();
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();

void Reset_Handler();
void fw_reset_c();
void Default_Handler();
void HardFault_Handler();
void fw_fault_c(const std::uint32_t* frame, std::uint32_t exc_return);
}

// The application's main(). Declared through an asm label: ISO C++ forbids calling ::main.
extern "C" int fw_application_main() __asm__("main");

namespace {
constexpr std::uint32_t kStackPaint = 0x5AC3A55Cu;
}

// ---------------------------------------------------------------------------------------------
// Vector table: initial SP, then the 15 system exception vectors. External interrupts are not
// used by test firmware (none is enabled), so the table stops at SysTick.
using Vector = void (*)();
extern "C" __attribute__((section(".isr_vector"), used)) const Vector fw_vector_table[16] = {
    reinterpret_cast<Vector>(__stack_top),  //  0 initial main stack pointer
    Reset_Handler,                          //  1 reset
    Default_Handler,                        //  2 NMI
    HardFault_Handler,                      //  3 HardFault
    Default_Handler,                        //  4 MemManage
    Default_Handler,                        //  5 BusFault
    Default_Handler,                        //  6 UsageFault
    nullptr, nullptr, nullptr, nullptr,     //  7-10 reserved
    Default_Handler,                        // 11 SVCall
    Default_Handler,                        // 12 DebugMonitor
    nullptr,                                // 13 reserved
    Default_Handler,                        // 14 PendSV
    Default_Handler,                        // 15 SysTick
};

// ---------------------------------------------------------------------------------------------
// The first instructions after reset. Naked and in assembly because the FPU must be on before
// any compiled code runs: with -mfloat-abi=hard the compiler may use FP registers anywhere
// (even for plain copies), and an FP instruction with CP10/CP11 disabled is a UsageFault.
extern "C" __attribute__((naked, noreturn)) void Reset_Handler() {
  __asm volatile(
      "movw r0, #:lower16:__stack_top   \n"  // SP = top of RAM, also when entered by a
      "movt r0, #:upper16:__stack_top   \n"  // bootloader or debugger jump
      "mov  sp, r0                      \n"
      "movw r0, #0xED88                 \n"  // CPACR = 0xE000ED88
      "movt r0, #0xE000                 \n"
      "ldr  r1, [r0]                    \n"
      "orr  r1, r1, #(0xF << 20)        \n"  // CP10, CP11 = full access (bits 20-23)
      "str  r1, [r0]                    \n"
      "dsb                              \n"
      "isb                              \n"
      "b    fw_reset_c                  \n");
}

extern "C" __attribute__((noreturn, used)) void fw_reset_c() {
  // .data: copy its initial image from flash to RAM.
  for (std::uint32_t *src = _sidata, *dst = _sdata; dst < _edata;) *dst++ = *src++;
  // .bss: zero.
  for (std::uint32_t* dst = _sbss; dst < _ebss;) *dst++ = 0;
  // Paint the stack budget (top __stack_size bytes of RAM) below the current SP, leaving 64
  // bytes for this frame.
  {
    std::uint32_t* sp;
    __asm volatile("mov %0, sp" : "=r"(sp));
    std::uint32_t* end = sp - 16;
    for (volatile std::uint32_t* p = __stack_paint_bottom; p < end; ++p) *p = kStackPaint;
  }
  // C++ static constructors (and C constructor functions).
  for (void (**f)() = __preinit_array_start; f < __preinit_array_end; ++f) (*f)();
  for (void (**f)() = __init_array_start; f < __init_array_end; ++f) (*f)();

  const int rc = fw_application_main();
  // Static destructors are not run (nothing to clean up on a bare-metal target).
  fw::exit(rc);
}

// ---------------------------------------------------------------------------------------------
// Faults: report and exit with fw::exit_fault so a test never hangs.
namespace {
void print_reg(const char* name, std::uint32_t v) noexcept {
  fw::print(name);
  fw::print_hex(v);
}
}  // namespace

extern "C" __attribute__((naked)) void HardFault_Handler() {
  __asm volatile(
      "tst   lr, #4       \n"  // EXC_RETURN bit 2: which stack holds the exception frame
      "ite   eq           \n"
      "mrseq r0, msp      \n"
      "mrsne r0, psp      \n"
      "mov   r1, lr       \n"
      "b     fw_fault_c   \n");
}

extern "C" __attribute__((noreturn, used)) void fw_fault_c(const std::uint32_t* frame,
                                                           std::uint32_t exc_return) {
  volatile const std::uint32_t* scb = reinterpret_cast<volatile const std::uint32_t*>(0xE000ED00u);
  std::uint32_t ipsr;
  __asm volatile("mrs %0, ipsr" : "=r"(ipsr));
  fw::print("\n*** FAULT: exception ");
  fw::print_int(static_cast<long long>(ipsr & 0x1FFu));
  print_reg(" pc=", frame[6]);
  print_reg(" lr=", frame[5]);
  print_reg(" sp=", reinterpret_cast<std::uint32_t>(frame));
  print_reg(" exc_return=", exc_return);
  print_reg("\n    CFSR=", scb[0x28 / 4]);
  print_reg(" HFSR=", scb[0x2C / 4]);
  print_reg(" MMFAR=", scb[0x34 / 4]);
  print_reg(" BFAR=", scb[0x38 / 4]);
  fw::print("\n");
  fw::exit(fw::exit_fault);
}

extern "C" __attribute__((naked)) void Default_Handler() {
  __asm volatile(
      "tst   lr, #4       \n"
      "ite   eq           \n"
      "mrseq r0, msp      \n"
      "mrsne r0, psp      \n"
      "mov   r1, lr       \n"
      "b     fw_fault_c   \n");
}

// ---------------------------------------------------------------------------------------------
namespace fw {

std::size_t stack_high_water() noexcept {
  const volatile std::uint32_t* p = __stack_paint_bottom;
  const volatile std::uint32_t* top = __stack_top;
  while (p < top && *p == kStackPaint) ++p;
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(top) -
                                  reinterpret_cast<std::uintptr_t>(p));
}

std::size_t stack_capacity() noexcept {
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(__stack_top) -
                                  reinterpret_cast<std::uintptr_t>(__stack_limit));
}

std::size_t stack_budget() noexcept {
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(__stack_top) -
                                  reinterpret_cast<std::uintptr_t>(__stack_paint_bottom));
}

bool report_stack() noexcept {
  const std::size_t used = stack_high_water();
  print("stack high water: ");
  print_int(static_cast<long long>(used));
  print(" bytes (budget ");
  print_int(static_cast<long long>(stack_budget()));
  print(", free RAM ");
  print_int(static_cast<long long>(stack_capacity()));
  print(")\n");
  if (used < stack_budget()) return true;
  print("FAILED: stack budget exceeded\n");
  return false;
}

const char* cpu_name() noexcept { return PROXGEN_FW_CPU_NAME; }

}  // namespace fw
