// The generated joint-space functions against their generic twins in the same
// run, per case: <case>/<function>/generated and <case>/<function>/generic
// (inverse_dynamics with random qdd and lambda, nonlinear_effects,
// mass_matrix = crba, mass_matrix_inverse). States (and qdd, lambda) are drawn
// before any timing and cycled inside the timed loop, as bench_suite.cpp does.
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "algorithms/crba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/rnea.hpp"
#include "cases/cases.hpp"
#include "joint_space_solvers.hpp"
#include "model/state.hpp"

namespace {

// A case of cases.yaml with 1000 random states (a fixed seed), loaded once per
// case for the whole run (the suite's pool size, bench/common.hpp).
struct BenchCase {
  std::string name;
  proxgen::System sys;
  std::vector<proxgen::State> states;
};

const BenchCase* findCase(const std::string& name) {
  static std::vector<std::unique_ptr<BenchCase>> loaded;
  auto c = std::make_unique<BenchCase>();
  c->name = name;
  c->sys = proxgen::loadCaseSystem(proxgen::loadCase(PROXGEN_BENCH_CASES_FILE, name));
  std::mt19937 rng(1);
  for (int k = 0; k < 1000; ++k) c->states.push_back(proxgen::randomState(c->sys.model, rng));
  loaded.push_back(std::move(c));
  return loaded.back().get();
}

// One case's inputs in the generated Scalar and in double (VecX), kept for the whole run.
template <class Scalar>
struct Inputs {
  int n = 0, nq = 0, nv = 0, nc = 0;
  std::vector<Scalar> q, v, qdd, lambda;
  std::vector<proxgen::VecX> qdd64, lambda64;
  const Scalar* at(const std::vector<Scalar>& x, int size, int k) const { return x.data() + std::size_t(k) * size; }
};

template <class Scalar>
std::shared_ptr<Inputs<Scalar>> inputsOf(const BenchCase& c) {
  auto in = std::make_shared<Inputs<Scalar>>();
  const proxgen::Model& m = c.sys.model;
  in->n = int(c.states.size());
  in->nq = m.nq, in->nv = m.nv, in->nc = c.sys.nc;
  std::mt19937 rng(20261201);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const proxgen::State& s : c.states) {
    proxgen::VecX qdd(m.nv), lambda(c.sys.nc);
    for (int k = 0; k < m.nv; ++k) qdd[k] = normal(rng);
    for (int k = 0; k < c.sys.nc; ++k) lambda[k] = 10.0 * normal(rng);
    for (int k = 0; k < m.nq; ++k) in->q.push_back(Scalar(s.q[k]));
    for (int k = 0; k < m.nv; ++k) in->v.push_back(Scalar(s.v[k])), in->qdd.push_back(Scalar(qdd[k]));
    for (int k = 0; k < c.sys.nc; ++k) in->lambda.push_back(Scalar(lambda[k]));
    in->qdd64.push_back(qdd);
    in->lambda64.push_back(lambda);
  }
  return in;
}

template <class F>
void loop(benchmark::State& st, int n, const F& call) {
  int k = 0;
  for (auto _ : st) {
    call(k);
    benchmark::ClobberMemory();
    if (++k == n) k = 0;
  }
}

template <class Scalar, class Workspace, class Id, class Nle, class Mm, class Minv>
void registerCase(const char* name, Id id, Nle nle, Mm mm, Minv minv) {
  const BenchCase& c = *findCase(name);
  const auto in = inputsOf<Scalar>(c);
  const auto ws = std::make_shared<Workspace>();
  const auto out = std::make_shared<std::vector<Scalar>>(std::size_t(in->nv * in->nv + 1));
  const auto data = std::make_shared<proxgen::Data>(c.sys);
  const std::string base = c.name + "/";
  const auto reg = [&](const std::string& what, auto call) {
    benchmark::RegisterBenchmark((base + what).c_str(), [=](benchmark::State& st) { loop(st, in->n, call); })
        ->Unit(benchmark::kMicrosecond);
  };
  reg("inverse_dynamics/generated", [=](int k) {
    id(in->at(in->q, in->nq, k), in->at(in->v, in->nv, k), in->at(in->qdd, in->nv, k), in->at(in->lambda, in->nc, k), *ws,
       out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("inverse_dynamics/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(
        proxgen::inverseDynamics(c.sys, *data, c.states[std::size_t(k)].q, c.states[std::size_t(k)].v,
                                 in->qdd64[std::size_t(k)], c.sys.nc ? &in->lambda64[std::size_t(k)] : nullptr)
            .data());
  });
  reg("nonlinear_effects/generated", [=](int k) {
    nle(in->at(in->q, in->nq, k), in->at(in->v, in->nv, k), *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("nonlinear_effects/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(
        proxgen::nonLinearEffects(c.sys, *data, c.states[std::size_t(k)].q, c.states[std::size_t(k)].v).data());
  });
  reg("mass_matrix/generated", [=](int k) {
    mm(in->at(in->q, in->nq, k), *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("mass_matrix/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::crba(c.sys, *data, c.states[std::size_t(k)].q).data());
  });
  reg("mass_matrix_inverse/generated", [=](int k) {
    minv(in->at(in->q, in->nq, k), *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("mass_matrix_inverse/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::massMatrixInverse(c.sys, *data, c.states[std::size_t(k)].q).data());
  });
}

#define PROXGEN_BENCH_REGISTER(CASE, NS)                                                                            \
  registerCase<NS::Scalar, NS::Workspace>(#CASE, NS::inverse_dynamics, NS::nonlinear_effects, NS::mass_matrix, \
                                          NS::mass_matrix_inverse);

}  // namespace

int main(int argc, char** argv) {
  PROXGEN_BENCH_JOINT_SPACE_CASES(PROXGEN_BENCH_REGISTER)
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
