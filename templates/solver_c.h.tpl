R"proxgen({banner}//
// The C interface of the solver in {name}.hpp (docs/design.md, "The C
// interface"), for C firmware and other languages: plain arrays, a work buffer
// the caller provides, nothing allocated, nothing thrown. The definitions are
// in {name}_c.cpp (C++, compiled with {name}.cpp: proxgen_add_solver does both).
// Arrays and conventions are {name}.hpp's: q[{prefix}_NQ], v and tau[{prefix}_NV],
// lambda[{prefix}_NC] in layout order; the scalar is {scalar}.
// Work buffer: {prefix}_WORK_SIZE bytes ({prefix}_work_size()) aligned to
// {prefix}_WORK_ALIGN ({prefix}_work_align()), e.g. a static {scalar} array of
// {prefix}_WORK_SIZE / sizeof({scalar}) entries; it holds everything one call
// writes. Calls with different buffers may run at the same time (in threads);
// calls with one buffer may not. None of the arrays may point into the buffer.
#ifndef {guard}
#define {guard}

#include <stddef.h>

#ifdef __cplusplus
extern "C" {{
#endif

/* Called from C++ the functions are noexcept (their C++ definitions are). */
#ifndef PROXGEN_C_NOEXCEPT
#ifdef __cplusplus
#define PROXGEN_C_NOEXCEPT noexcept
#else
#define PROXGEN_C_NOEXCEPT
#endif
#endif

#define {prefix}_NQ {nq}    /* configuration */
#define {prefix}_NV {nv}    /* velocity */
#define {prefix}_NC {nc}    /* constraint rows */
#define {prefix}_NCONS {ncons} /* constraints in the layout (each 3 or 6 rows) */
#define {prefix}_WORK_SIZE {work_size}
#define {prefix}_WORK_ALIGN {work_align}
{constraints}
size_t {prefix}_work_size(void) PROXGEN_C_NOEXCEPT;
size_t {prefix}_work_align(void) PROXGEN_C_NOEXCEPT;
{declarations}
#ifdef __cplusplus
}}  /* extern "C" */
#endif

#endif /* {guard} */
)proxgen"
