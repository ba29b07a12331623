// proxgen eval: runs one generic solver on states read from JSON and prints the
// results as JSON, keyed by joint and constraint names (docs/design.md,
// "Conventions"). One state object gives one result object, a list gives a list.
// The residual ||J qdd + gamma - aStar|| is recomputed here from the solver's
// output (constraintJacobian), so it checks the answer rather than repeating
// what the solver believes.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/dense_reference.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/prox_ltl.hpp"
#include "algorithms/prox_ltls.hpp"
#include "algorithms/prox_pv.hpp"
#include "cli/commands.hpp"
#include "model/error.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"

namespace proxgen::cli {
namespace {

using ordered_json = nlohmann::ordered_json;

inline constexpr double kMaxIterations = 1e6;  // beyond this a typo, not a request
const char* const kCommandLine = "command line";

struct EvalOptions {
  std::string urdf, layout, state, algorithm = "caba", iterations, mu;
  std::string compute;  // --compute: the dynamics library instead of a solver (compute.cpp)
};

enum class Algorithm { Caba, Pv, Ltl, Ltls, Dense };

Algorithm parseAlgorithm(const std::string& name) {
  if (name == "caba") return Algorithm::Caba;
  if (name == "pv") return Algorithm::Pv;
  if (name == "ltl") return Algorithm::Ltl;
  if (name == "ltls") return Algorithm::Ltls;
  if (name == "dense") return Algorithm::Dense;
  fail(kCommandLine, "--algorithm", fmt::format("unknown algorithm {} (expected caba, pv, ltl, ltls or dense)", quoted(name)));
}

// A whole-string, locale-independent number (from_chars never looks at the locale).
double parseNumber(const std::string& text, const char* option) {
  double x = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, x);
  if (ec == std::errc::result_out_of_range) fail(kCommandLine, option, fmt::format("{} is out of range", quoted(text)));
  if (text.empty() || ec != std::errc() || ptr != end) fail(kCommandLine, option, fmt::format("{} is not a number", quoted(text)));
  if (!std::isfinite(x)) fail(kCommandLine, option, fmt::format("{} is not finite", quoted(text)));
  return x;
}

double parseMu(const std::string& text) {
  const double mu = parseNumber(text, "--mu");
  if (!(mu > 0)) fail(kCommandLine, "--mu", fmt::format("the penalty mu must be > 0, got {}", quoted(text)));
  return mu;
}

int parseIterations(const std::string& text) {
  const double k = parseNumber(text, "--iterations");
  if (k != std::floor(k)) fail(kCommandLine, "--iterations", fmt::format("{} is not an integer", quoted(text)));
  if (k < 0 || k > kMaxIterations)
    fail(kCommandLine, "--iterations", fmt::format("{} is outside [0, {}]", quoted(text), kMaxIterations));
  return int(k);
}

struct Answer {
  VecX qdd, lambda;
};

Answer solve(const System& sys, Data& d, Algorithm algorithm, const State& s, double mu, int K) {
  if (algorithm == Algorithm::Dense) {
    Answer a;
    denseProx(assembleDense(sys, s.q, s.v, s.tau), mu, K, a.qdd, a.lambda);
    return a;
  }
  switch (algorithm) {
    case Algorithm::Caba: constrainedAba(sys, d, s.q, s.v, s.tau, mu, K); break;
    case Algorithm::Pv: proxPv(sys, d, s.q, s.v, s.tau, mu, K); break;
    case Algorithm::Ltl: proxLtl(sys, d, s.q, s.v, s.tau, mu, K); break;
    case Algorithm::Ltls: proxLtls(sys, d, s.q, s.v, s.tau, mu, K); break;
    case Algorithm::Dense: break;
  }
  return {d.qdd, d.lambda};
}

/// ||J qdd + gamma - aStar|| at the state, from the constraint rows alone.
double constraintResidual(const System& sys, Data& d, const State& s, const VecX& qdd) {
  if (sys.nc == 0) return 0.0;
  constraintJacobian(sys, d, s.q, s.v);
  return (d.J * qdd + d.gamma - d.aStar).norm();
}

// Slots [at, at + n) as a number (n == 1) or a list.
ordered_json slotsJson(const VecX& x, int at, int n) {
  if (n == 1) return x[at];
  ordered_json out = ordered_json::array();
  for (int k = 0; k < n; ++k) out.push_back(x[at + k]);
  return out;
}

// Keyed by joint name, in joint order (state.hpp's helpers sort keys alphabetically).
ordered_json qddJson(const Model& m, const VecX& qdd) {
  ordered_json out = ordered_json::object();
  for (int i = 1; i < m.numBodies(); ++i) out[m.bodies[i].joint.name] = slotsJson(qdd, m.bodies[i].joint.idx_v, m.bodies[i].joint.nv);
  return out;
}

// Keyed by constraint name, in layout order; always lists (rows of 3 or 6).
ordered_json lambdaJson(const System& sys, const VecX& lambda) {
  ordered_json out = ordered_json::object();
  for (const Constraint& c : sys.constraints) {
    ordered_json rows = ordered_json::array();
    for (int r = 0; r < c.rows(); ++r) rows.push_back(lambda[c.row + r]);
    out[c.name] = rows;
  }
  return out;
}

ordered_json resultJson(const System& sys, const Answer& a, const std::string& algorithm, double mu, int K, double residual) {
  return {{"qdd", qddJson(sys.model, a.qdd)}, {"lambda", lambdaJson(sys, a.lambda)}, {"iterations", K}, {"mu", mu},
          {"algorithm", algorithm}, {"residual", residual}};
}

// --- overflow: a result that is not finite is an error naming what overflowed

bool finite(const Mat6& x) { return x.allFinite(); }
bool finite(const Vec6& x) { return x.allFinite(); }

// The first non-finite quantity of one solve, named by body, joint or
// constraint ("" when all are finite). The body-wise intermediates every
// recursive algorithm fills (placements, velocities, accelerations, and for the
// articulated ones the articulated inertias and bias forces) are checked
// before the outputs: the first quantity that overflowed says why the rest did.
std::string firstNonFinite(const System& sys, const Data& d, Algorithm algorithm, const Answer& a, double residual) {
  const Model& m = sys.model;
  if (algorithm != Algorithm::Dense) {
    for (int i = 1; i < m.numBodies(); ++i) {
      const std::string body = fmt::format("body {}", quoted(m.bodies[i].link));
      if (!d.oMi[i].R.allFinite() || !d.oMi[i].p.allFinite()) return body + " placement";
      if (!finite(d.v[i])) return body + " velocity";
      if (!finite(d.a[i])) return body + " acceleration";
    }
    if (algorithm == Algorithm::Caba || algorithm == Algorithm::Pv)
      for (int i = 1; i < m.numBodies(); ++i) {
        const std::string body = fmt::format("body {}", quoted(m.bodies[i].link));
        if (!finite(d.IA[i])) return body + " articulated inertia";
        if (!finite(d.pA[i])) return body + " articulated bias force";
      }
  }
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    for (int k = 0; k < j.nv; ++k)
      if (!std::isfinite(a.qdd[j.idx_v + k])) return fmt::format("qdd of joint {}", quoted(j.name));
  }
  for (const Constraint& c : sys.constraints)
    for (int r = 0; r < c.rows(); ++r)
      if (!std::isfinite(a.lambda[c.row + r])) return fmt::format("lambda of constraint {}", quoted(c.name));
  if (!std::isfinite(residual)) return "the constraint residual";
  return "";
}

void runEval(const EvalOptions& o) {
  if (!o.compute.empty())
    return runCompute(o.urdf, o.layout, o.state, o.compute, o.mu.empty() ? 0.0 : parseMu(o.mu),
                      o.iterations.empty() ? -1 : parseIterations(o.iterations));
  const Algorithm algorithm = parseAlgorithm(o.algorithm);
  const System sys = loadSystem(o.urdf, o.layout);
  const double mu = o.mu.empty() ? sys.mu : parseMu(o.mu);
  const int K = o.iterations.empty() ? sys.iterations : parseIterations(o.iterations);
  bool isList = false;
  const std::vector<State> states = loadStates(sys.model, o.state, &isList);

  Data d(sys);
  ordered_json results = ordered_json::array();
  for (std::size_t k = 0; k < states.size(); ++k) {
    const State& s = states[k];
    const Answer a = solve(sys, d, algorithm, s, mu, K);
    const std::string overflowed = firstNonFinite(sys, d, algorithm, a, 0.0);
    const double residual = overflowed.empty() ? constraintResidual(sys, d, s, a.qdd) : 0.0;
    const std::string what = overflowed.empty() ? firstNonFinite(sys, d, algorithm, a, residual) : overflowed;
    // JSON has no infinity: nlohmann would print null and exit 0 with no answer.
    if (!what.empty())
      fail(o.state, isList ? fmt::format("[{}]", k) : "",
           fmt::format("{} is not finite: {} overflowed double at this state (mu {}, K {}); the inputs are too "
                       "large or too small for the dynamics",
                       what, o.algorithm, mu, K));
    results.push_back(resultJson(sys, a, o.algorithm, mu, K, residual));
  }
  // Printed only once everything succeeded: an error leaves stdout empty.
  // nlohmann prints the shortest decimal that reads back as the same double.
  const std::string out = (isList ? results : results.at(0)).dump(2) + "\n";
  std::fputs(out.c_str(), stdout);
}

}  // namespace

void addEval(CLI::App& app) {
  auto opts = std::make_shared<EvalOptions>();
  auto* cmd = app.add_subcommand("eval", "run a generic solver on states (JSON) and print qdd and multipliers as JSON");
  cmd->add_option("urdf", opts->urdf, "robot URDF")->required();
  cmd->add_option("--layout", opts->layout, "constraint layout (YAML)")->required();
  cmd->add_option("--state", opts->state, "state JSON: one {q, v, tau} object or a list")->required();
  cmd->add_option("--algorithm", opts->algorithm, "caba | pv | ltl | ltls | dense (default caba)");
  cmd->add_option("--iterations", opts->iterations, "multiplier updates K in [0, 1e6] (default: the layout's)")->type_name("INT");
  cmd->add_option("--mu", opts->mu, "penalty mu > 0, finite (default: the layout's)")->type_name("FLOAT");
  cmd->add_option("--compute", opts->compute, "print a dynamics-library quantity instead (docs/dynamics.md)")->type_name("QUANTITY");
  cmd->callback([opts] { runEval(*opts); });
}

}  // namespace proxgen::cli
