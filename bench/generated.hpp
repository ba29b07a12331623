// Adapter from a generated solver (README, "The generated solver": namespace
// with Scalar, nq, nv, nc, Settings, Workspace, constrained_aba, prox_pv) to the
// benchmark's Solver interface. The build writes generated_solvers.cpp, which
// includes every generated header and lists one GeneratedEntry per case.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "common.hpp"
#include "model/error.hpp"

namespace proxgen::bench {

using SolverFactory = std::unique_ptr<Solver> (*)(const BenchCase&);

struct GeneratedEntry {
  const char* caseName;
  SolverFactory caba, pv;
};

/// The generated solvers this build has (empty with PROXGEN_BENCH_GENERATED off).
const std::vector<GeneratedEntry>& generatedSolvers();

/// Ws, Settings, Scalar, nq, nv, nc come from the generated namespace; Entry is
/// its constrained_aba or prox_pv.
template <class Scalar, class Ws, class Settings, int NQ, int NV, int NC, auto Entry>
class GeneratedSolver final : public Solver {
 public:
  explicit GeneratedSolver(const BenchCase& c) : n_(int(c.states.size())) {
    const Model& m = c.sys.model;
    if (m.nq != NQ || m.nv != NV || c.sys.nc != NC)
      throw Error("case " + c.name + ": the generated solver's sizes (nq, nv, nc) differ from the model's");
    // Inputs in the solver's scalar type, one contiguous block per vector.
    q_.resize(std::size_t(n_) * NQ);
    v_.resize(std::size_t(n_) * NV);
    tau_.resize(std::size_t(n_) * NV);
    for (int k = 0; k < n_; ++k) {
      const State& s = c.states[k];
      for (int i = 0; i < NQ; ++i) q_[std::size_t(k) * NQ + i] = Scalar(s.q[i]);
      for (int i = 0; i < NV; ++i) v_[std::size_t(k) * NV + i] = Scalar(s.v[i]);
      for (int i = 0; i < NV; ++i) tau_[std::size_t(k) * NV + i] = Scalar(s.tau[i]);
    }
    settings_.mu = Scalar(kMu);
    settings_.iterations = kIterations;
    ws_ = std::make_unique<Ws>();
  }

  void solve(int k) override {
    Entry(q_.data() + std::size_t(k) * NQ, v_.data() + std::size_t(k) * NV, tau_.data() + std::size_t(k) * NV,
          settings_, *ws_, qdd_, lambda_);
  }
  const void* output() const override { return qdd_; }

  static std::unique_ptr<Solver> make(const BenchCase& c) { return std::make_unique<GeneratedSolver>(c); }

 private:
  int n_;
  std::vector<Scalar> q_, v_, tau_;
  Settings settings_;
  std::unique_ptr<Ws> ws_;
  Scalar qdd_[NV > 0 ? NV : 1] = {};
  Scalar lambda_[NC > 0 ? NC : 1] = {};
};

}  // namespace proxgen::bench

/// One GeneratedEntry for the generated namespace NS of case CASE.
#define PROXGEN_BENCH_GENERATED_ENTRY(CASE, NS)                                                                   \
  ::proxgen::bench::GeneratedEntry {                                                                             \
    CASE,                                                                                                        \
        &::proxgen::bench::GeneratedSolver<NS::Scalar, NS::Workspace, NS::Settings, NS::nq, NS::nv, NS::nc,      \
                                           &NS::constrained_aba>::make,                                          \
        &::proxgen::bench::GeneratedSolver<NS::Scalar, NS::Workspace, NS::Settings, NS::nq, NS::nv, NS::nc,      \
                                           &NS::prox_pv>::make                                                   \
  }
