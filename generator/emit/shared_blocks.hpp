// Shared blocks (issue 20's isomorphic subtrees): after the passes are printed,
// the body blocks that are the same code up to their constants, the workspace
// members they touch and the offsets of their inputs (a left and a right leg,
// four legs, the columns of one body in the derivatives' sweep) become one
// kernel, a function over a constant table per block, called where each block
// was. The arithmetic is the same statement for statement (a constant read
// from a table instead of a literal: the same double), so the results are the
// same bit for bit; the code is smaller. That pays where an entry point's code
// does not fit the processor's first-level instruction cache and costs the
// calls' few instructions where it does (docs/emitter.md, "Shared blocks"), so
// the emitter offers only the parts of large entry points (`eligible`).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "emit/members.hpp"

namespace proxgen::emit {

struct SharedKernel {
  std::string name;                  // shared_<k>
  std::vector<std::string> blocks;   // each block's comment line (its body), in order of the file
  std::vector<std::string> bodies;   // the bodies of those blocks, each once, in that order
  int pairs = 0;                     // calls of its paired form shared_<k>_x2, two blocks each
  int signs = 0;                     // a signed pair's kernel: the signs it turns in one lane (else 0)
};

struct SharedParts {
  std::string parts;  // the kernels and their tables, then the part functions calling them
  std::vector<SharedKernel> kernels;
};

/// `parts`: the part functions as FunctionWriter prints them; `eligible(name)`:
/// whether the blocks of part function `name` may be shared. Blocks that read
/// anything but their part's parameters, the workspace members and their own
/// temporaries are left as they are. `pairs`: two blocks of a kernel, one
/// right after the other in a part and independent, run as one call of the
/// kernel's paired form (docs/emitter.md, "Blocks in pairs").
SharedParts shareBlocks(const std::string& parts, const Members& ws,
                        const std::function<bool(const std::string&)>& eligible, bool pairs);

/// Entry points whose code is at least this many operations (once + per
/// iteration, the code's size rather than its work) share their blocks: at
/// some 13 bytes of x86-64 per printed operation, about 40 KB, above the 32 KB
/// of a first-level instruction cache. Measured (docs/benchmarks.md): under
/// it sharing was 1.01-1.06 of the time, over it 0.76-0.97.
inline constexpr long kSharedBlocksMinOps = 3000;

}  // namespace proxgen::emit
