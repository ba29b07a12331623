// `generate --batch W`: the batched solvers (docs/batch.md), two more files
// beside NAME.hpp and NAME.cpp, which stay byte for byte what they are
// without --batch. NAME_batch.cpp holds NAME.cpp's functions a second time,
// with Scalar the runtime's proxgen_rt::lanes<Scalar, W> (one value of each of
// W states) and the Workspace over lanes, plus the entry points of the header
// contract (constrained_aba_batch, prox_pv_batch, the _many forms).
#pragma once

#include <string>

#include "emit/emitter.hpp"

namespace proxgen::emit {

/// The lane widths --batch accepts.
bool validBatchWidth(int width);

/// --batch's value as given on the command line (not `given`: 0, no batched
/// files); anything but 2, 4, 8 or 16, the empty text too, is refused with one
/// line naming the option and the valid widths (proxgen::Error, "command line"
/// as the file).
int parseBatchWidth(const std::string& text, bool given);

struct BatchFiles {
  std::string headerName, header;  // NAME_batch.hpp
  std::string sourceName, source;  // NAME_batch.cpp
};

/// The batched files of the solver `scalar` (emitSolver's NAME.hpp and
/// NAME.cpp, holding constrained_aba and prox_pv), over `width` lanes: the two
/// solvers' _batch and _many forms, and those of each library function the
/// solver holds (inverse_dynamics ... constraint_wrenches; docs/batch.md).
/// Throws proxgen::Error when the solver lacks one of the two solvers or the
/// width is not 2, 4, 8 or 16.
BatchFiles batchFiles(const SolverFiles& scalar, int width);

}  // namespace proxgen::emit
