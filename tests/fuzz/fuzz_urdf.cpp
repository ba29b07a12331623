// URDF text -> Model, with a fixed and with a floating base. A model that loads
// is bound to a one-constraint layout (a 6D weld of its last link) and run
// through ABA, constrainedABA and proxPV once, so whatever the loader accepts
// is also safe for the solvers (ASan/UBSan watch the arithmetic's indexing).
#include <cstddef>
#include <cstdint>
#include <string>

#include "algorithms/aba.hpp"
#include "algorithms/constrained_aba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/prox_pv.hpp"
#include "fuzz_common.hpp"
#include "model/urdf.hpp"

namespace {

// Larger models are valid but only slow the fuzzer down; loading is what is fuzzed.
constexpr int kMaxSolvedDofs = 64;

void solveOnce(proxgen::Model model) {
  using namespace proxgen;
  if (model.nv > kMaxSolvedDofs) return;
  Layout layout;
  layout.floatingBase = model.floatingBase;
  if (model.frames.size() > 1) {
    Constraint c;
    c.name = "fuzz_weld";
    c.link = model.frames.back().name;
    layout.constraints.push_back(c);
  }
  const System sys = bindLayout(std::move(model), layout);
  Data d(sys);
  const VecX q = sys.model.neutral(), v = VecX::Zero(sys.model.nv), tau = VecX::Zero(sys.model.nv);
  aba(sys, d, q, v, tau);
  constrainedAba(sys, d, q, v, tau, sys.mu, 2);
  proxPv(sys, d, q, v, tau, sys.mu, 2);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string xml(reinterpret_cast<const char*>(data), size);
  for (bool floating : {false, true}) {
    PROXGEN_FUZZ_GUARD(solveOnce(proxgen::parseUrdf(xml, "fuzz.urdf", floating)));
  }
  return 0;
}
