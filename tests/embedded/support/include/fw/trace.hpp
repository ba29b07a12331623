// Region markers for counting executed instructions under qemu (tests/embedded/count_insns.py).
// Wrap the code to measure:   fw::trace_begin(); solver(...); fw::trace_end();
// The calls cost a few instructions and do nothing else, so they can stay in test firmware.
#pragma once

extern "C" {
void fw_trace_begin() noexcept;
void fw_trace_end() noexcept;
}

namespace fw {
inline void trace_begin() noexcept { fw_trace_begin(); }
inline void trace_end() noexcept { fw_trace_end(); }
}  // namespace fw
