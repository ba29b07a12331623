// proxgen verify: generate a solver into a temporary folder (in-process, the
// library's generateFiles and writeFiles), compile it with the compiler proxgen
// was built with and the options every generated solver is built with
// (proxgen_solver_compile_options in cmake/ProxgenAddSolver.cmake, baked in at
// configure time), run it on random states and compare qdd and the multipliers
// with the generic solvers at K = 1, 2, 3 and at convergence, within the
// conditioning-aware bounds the generated-solver tests use (verify/compare.hpp).
// This is what a user runs on their own robot before trusting a generated solver.
// The joint-space functions the solver holds (layout functions:, --functions)
// are run on the same states with random qdd and lambda and compared with their
// generic twins (verify/compare.hpp, compareLibraryWithGeneric).
// With --batch W it also generates the batched solvers (NAME_batch.*,
// docs/batch.md) and checks every lane of their _many and _batch forms against
// the scalar generated solver on the same states, bit for bit (everything is
// then compiled with -ffp-contract=off: docs/batch.md, "Lane by lane").
//   proxgen verify robot.urdf --layout layout.yaml [--samples N] [--functions a,b|all] [--batch W]
//   proxgen verify --cases cases.yaml --case NAME [--samples N] [--functions a,b|all] [--batch W]
#include <fmt/format.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "algorithms/data.hpp"
#include "cases/cases.hpp"
#include "cli/commands.hpp"
#include "emit/batch.hpp"
#include "emit/generate.hpp"
#include "emit/output.hpp"
#include "model/error.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "verify/compare.hpp"

namespace fs = std::filesystem;

namespace proxgen::cli {
namespace {

struct VerifyOptions {
  std::string urdf, layout, cases, caseName, scalar = "double", keep, functions;
  int samples = 20;
  unsigned seed = 1;
  double tolerance = 0;  // 0: the conditioning-aware bounds of verify/compare.hpp
  int converged = 100;
  std::string batchText;  // --batch W as given (parseBatchWidth)
  int batch = 0;          // its width (0: no batched solvers)
};

// Runs argv (no shell), stdout+stderr to `log`; returns the exit status. The
// child is known to the interrupt handler, which kills it before cleaning up.
int runProcess(const std::vector<std::string>& argv, const fs::path& log, const fs::path& in = {}) {
  const pid_t pid = fork();
  if (pid < 0) throw Error(fmt::format("verify: cannot start {} ({})", argv[0], std::strerror(errno)));
  if (pid == 0) {
    setpgid(0, 0);  // its own group: the interrupt handler stops it with its children
    if (!in.empty() && !std::freopen(in.c_str(), "r", stdin)) _exit(126);
    if (!std::freopen(log.c_str(), "w", stdout)) _exit(126);
    if (dup2(fileno(stdout), fileno(stderr)) < 0) _exit(126);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  setpgid(pid, pid);  // also here: the group exists before the handler may need it
  emit::setInterruptChild(pid);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  emit::setInterruptChild(0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The lines of a compiler log that say what is wrong (the first few), one
// message: a log does not reach the terminal raw (main escapes the message).
std::string firstErrors(const std::string& log) {
  std::istringstream in(log);
  std::string line, out;
  int shown = 0;
  while (std::getline(in, line) && shown < 3)
    if (line.find("error") != std::string::npos) {
      out += (out.empty() ? "" : " | ") + line;
      ++shown;
    }
  return out.empty() ? log.substr(0, 300) : out;
}

// Options of every compile of generated code (configure time, generator/CMakeLists.txt).
std::vector<std::string> solverCompileOptions() {
  std::vector<std::string> out;
  std::istringstream in(PROXGEN_SOLVER_COMPILE_OPTIONS);
  for (std::string o; in >> o;) out.push_back(o);
  return out;
}

// The runtime headers: next to an installed binary (<prefix>/include), else the source tree.
fs::path runtimeDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "include";
    if (fs::exists(installed / "proxgen" / "runtime.hpp")) return installed;
  }
  return PROXGEN_RUNTIME_DIR;
}

// The driver reads samples (q, v, tau, mu, K) from stdin and prints, per sample,
// qdd and lambda of constrained_aba then prox_pv, one number per line (none
// unless the solver holds both); then library samples (q, v, qdd, lambda) and,
// per sample, what each joint-space function it holds returns (compare.hpp's
// LibraryAnswer order: tau, h, M, Minv, then ConstraintAnswer's: X, J, gamma,
// G, Ginv at the layout's mu, W from the sample's lambda). verify.cpp prepends a
// PROXGEN_VERIFY_HAS_<FUNCTION> 1 line per function held.
constexpr const char* kDriver = R"(// proxgen verify driver (temporary)
#include <cstdio>
#include "proxgen_verify_solver.hpp"
namespace s = proxgen_verify_solver;
static s::Workspace w;
[[maybe_unused]] static bool readAll(s::Scalar* x, int n) {
  double y = 0;
  for (int k = 0; k < n; ++k) { if (std::scanf("%lf", &y) != 1) return false; x[k] = s::Scalar(y); }
  return true;
}
[[maybe_unused]] static void printAll(const s::Scalar* x, int n) {
  for (int k = 0; k < n; ++k) std::printf("%.17g\n", double(x[k]));
}
int main() {
  int n = 0;
  if (std::scanf("%d", &n) != 1) return 2;
#if PROXGEN_VERIFY_HAS_CONSTRAINED_ABA && PROXGEN_VERIFY_HAS_PROX_PV
  for (int t = 0; t < n; ++t) {
    s::Scalar q[s::nq], v[s::nv], tau[s::nv], qdd[s::nv], lambda[s::nc + 1];
    double x = 0;
    for (int k = 0; k < s::nq; ++k) { if (std::scanf("%lf", &x) != 1) return 2; q[k] = s::Scalar(x); }
    for (int k = 0; k < s::nv; ++k) { if (std::scanf("%lf", &x) != 1) return 2; v[k] = s::Scalar(x); }
    for (int k = 0; k < s::nv; ++k) { if (std::scanf("%lf", &x) != 1) return 2; tau[k] = s::Scalar(x); }
    s::Settings st;
    int K = 0;
    if (std::scanf("%lf %d", &x, &K) != 2) return 2;
    st.mu = s::Scalar(x);
    st.iterations = K;
    s::constrained_aba(q, v, tau, st, w, qdd, lambda);
    for (int k = 0; k < s::nv; ++k) std::printf("%.17g\n", double(qdd[k]));
    for (int k = 0; k < s::nc; ++k) std::printf("%.17g\n", double(lambda[k]));
    s::prox_pv(q, v, tau, st, w, qdd, lambda);
    for (int k = 0; k < s::nv; ++k) std::printf("%.17g\n", double(qdd[k]));
    for (int k = 0; k < s::nc; ++k) std::printf("%.17g\n", double(lambda[k]));
  }
#endif
  int m = 0;
  if (std::scanf("%d", &m) != 1) return 2;
  for (int t = 0; t < m; ++t) {
    static s::Scalar q[s::nq], v[s::nv], qdd[s::nv], lambda[s::nc + 1],
        out[s::nv * s::nv + 12 * s::ncons + s::nc * s::nv + s::nc * s::nc + 1];
    if (!readAll(q, s::nq) || !readAll(v, s::nv) || !readAll(qdd, s::nv) || !readAll(lambda, s::nc)) return 2;
    static_cast<void>(out);
#if PROXGEN_VERIFY_HAS_INVERSE_DYNAMICS
    s::inverse_dynamics(q, v, qdd, lambda, w, out);
    printAll(out, s::nv);
#endif
#if PROXGEN_VERIFY_HAS_NONLINEAR_EFFECTS
    s::nonlinear_effects(q, v, w, out);
    printAll(out, s::nv);
#endif
#if PROXGEN_VERIFY_HAS_MASS_MATRIX
    s::mass_matrix(q, w, out);
    printAll(out, s::nv * s::nv);
#endif
#if PROXGEN_VERIFY_HAS_MASS_MATRIX_INVERSE
    s::mass_matrix_inverse(q, w, out);
    printAll(out, s::nv * s::nv);
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_PLACEMENTS
    s::constraint_placements(q, w, out);
    printAll(out, 12 * s::ncons);
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_JACOBIAN
    s::constraint_jacobian(q, w, out);
    printAll(out, s::nc * s::nv);
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_DRIFT
    s::constraint_drift(q, v, w, out);
    printAll(out, s::nc);
#endif
#if PROXGEN_VERIFY_HAS_DELASSUS
    s::delassus(q, w, out);
    printAll(out, s::nc * s::nc);
#endif
#if PROXGEN_VERIFY_HAS_DELASSUS_INVERSE
    s::delassus_inverse(q, s::Settings{}, w, out);  // the layout's mu
    printAll(out, s::nc * s::nc);
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_WRENCHES
    s::constraint_wrenches(q, lambda, w, out);  // the sample's lambda
    printAll(out, 6 * s::ncons);
#endif
    // The derivatives; forward and constrained take the sample's qdd as tau.
    static s::Scalar d[6][(s::nv > s::nc ? s::nv : s::nc) * s::nv], r[2][s::nv + s::nc + 1];
    static_cast<void>(d);
    static_cast<void>(r);
#if PROXGEN_VERIFY_HAS_INVERSE_DYNAMICS_DERIVATIVES
    s::inverse_dynamics_derivatives(q, v, qdd, lambda, w, d[0], d[1]);
    printAll(d[0], s::nv * s::nv);
    printAll(d[1], s::nv * s::nv);
#endif
#if PROXGEN_VERIFY_HAS_FORWARD_DYNAMICS_DERIVATIVES
    s::forward_dynamics_derivatives(q, v, qdd, w, r[0], d[0], d[1], d[2]);
    printAll(r[0], s::nv);
    for (int k = 0; k < 3; ++k) printAll(d[k], s::nv * s::nv);
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINED_DYNAMICS_DERIVATIVES
    s::constrained_dynamics_derivatives(q, v, qdd, s::Settings{}, w, r[0], r[1], d[0], d[1], d[2], d[3], d[4], d[5]);
    printAll(r[0], s::nv);
    printAll(r[1], s::nc);
    for (int k = 0; k < 3; ++k) printAll(d[k], s::nv * s::nv);
    for (int k = 3; k < 6; ++k) printAll(d[k], s::nc * s::nv);
#endif
  }
  return 0;
}
)";

// The batched solvers' driver (--batch): reads the scalar driver's input, runs
// the trials sharing (mu, K) through constrained_aba_many and prox_pv_many (a
// count that is in general not a multiple of W), their first W states
// (repeated when fewer) through the _batch forms, then the library samples
// through the _many and _batch forms of each library function the solver
// holds (the PROXGEN_VERIFY_HAS_ lines, as the scalar driver's), and compares
// every answer with the scalar solver's or function's, bit for bit (NaN for
// NaN). Prints "<answers compared> <answers differing>".
constexpr const char* kBatchDriver = R"(// proxgen verify batch driver (temporary)
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>
#include "proxgen_verify_solver_batch.hpp"
namespace s = proxgen_verify_solver;
using S = s::Scalar;
constexpr int W = s::batch_width;
static s::Workspace w;
static s::BatchWorkspace bw;
static long compared = 0, differ = 0;
static void check(S batched, S scalar) {
  ++compared;
  if (!((std::isnan(batched) && std::isnan(scalar)) || std::memcmp(&batched, &scalar, sizeof batched) == 0)) ++differ;
}
// One library function on m samples: scalar(j, out) on sample j, batch(out) on
// the first W samples lane-interleaved (lane l: sample l mod m), many(out) on all m.
template <class Scalar1, class Batch, class Many>
[[maybe_unused]] static void library(int m, int size, Scalar1 scalar, Batch batch, Many many) {
  if (m <= 0) return;
  std::vector<S> expect(std::size_t(size) + 1), bout(std::size_t(size * W) + 1), mout(std::size_t(size * m) + 1);
  batch(bout.data());
  many(mout.data());
  for (int j = 0; j < m; ++j) {
    scalar(j, expect.data());
    for (int i = 0; i < size; ++i) check(mout[std::size_t(j * size + i)], expect[std::size_t(i)]);
    for (int l = j; l < W; l += m)
      for (int i = 0; i < size; ++i) check(bout[std::size_t(i * W + l)], expect[std::size_t(i)]);
  }
}
int main() {
  int n = 0;
  if (std::scanf("%d", &n) != 1 || n < 0) return 2;
  std::vector<S> q(std::size_t(n * s::nq)), v(std::size_t(n * s::nv)), tau(std::size_t(n * s::nv));
  std::vector<double> mu(static_cast<std::size_t>(n));
  std::vector<int> K(static_cast<std::size_t>(n));
  for (int t = 0; t < n; ++t) {
    double x = 0;
    for (int k = 0; k < s::nq; ++k) { if (std::scanf("%lf", &x) != 1) return 2; q[std::size_t(t * s::nq + k)] = S(x); }
    for (int k = 0; k < s::nv; ++k) { if (std::scanf("%lf", &x) != 1) return 2; v[std::size_t(t * s::nv + k)] = S(x); }
    for (int k = 0; k < s::nv; ++k) { if (std::scanf("%lf", &x) != 1) return 2; tau[std::size_t(t * s::nv + k)] = S(x); }
    if (std::scanf("%lf %d", &mu[std::size_t(t)], &K[std::size_t(t)]) != 2) return 2;
  }
  std::vector<char> done(static_cast<std::size_t>(n), 0);
  for (int t0 = 0; t0 < n; ++t0) {
    if (done[std::size_t(t0)]) continue;
    std::vector<int> group;
    for (int t = t0; t < n; ++t)
      if (!done[std::size_t(t)] && mu[std::size_t(t)] == mu[std::size_t(t0)] && K[std::size_t(t)] == K[std::size_t(t0)]) {
        group.push_back(t);
        done[std::size_t(t)] = 1;
      }
    const int m = int(group.size());
    std::vector<S> gq, gv, gtau;
    for (int t : group) {
      gq.insert(gq.end(), q.begin() + t * s::nq, q.begin() + (t + 1) * s::nq);
      gv.insert(gv.end(), v.begin() + t * s::nv, v.begin() + (t + 1) * s::nv);
      gtau.insert(gtau.end(), tau.begin() + t * s::nv, tau.begin() + (t + 1) * s::nv);
    }
    // The first W states of the group, lane-interleaved (lane l: state l mod m).
    std::vector<S> iq(std::size_t(s::nq * W)), iv(std::size_t(s::nv * W)), itau(std::size_t(s::nv * W));
    for (int l = 0; l < W; ++l) {
      const int j = l % m;
      for (int k = 0; k < s::nq; ++k) iq[std::size_t(k * W + l)] = gq[std::size_t(j * s::nq + k)];
      for (int k = 0; k < s::nv; ++k) iv[std::size_t(k * W + l)] = gv[std::size_t(j * s::nv + k)];
      for (int k = 0; k < s::nv; ++k) itau[std::size_t(k * W + l)] = gtau[std::size_t(j * s::nv + k)];
    }
    s::Settings st;
    st.mu = S(mu[std::size_t(t0)]);
    st.iterations = K[std::size_t(t0)];
    for (int f = 0; f < 2; ++f) {
      std::vector<S> qdd(std::size_t(m * s::nv)), lambda(std::size_t(m * s::nc + 1));
      std::vector<S> bqdd(std::size_t(s::nv * W)), blambda(std::size_t(s::nc * W + 1));
      if (f == 0) {
        s::constrained_aba_many(m, gq.data(), gv.data(), gtau.data(), st, bw, qdd.data(), lambda.data());
        s::constrained_aba_batch(iq.data(), iv.data(), itau.data(), st, bw, bqdd.data(), blambda.data());
      } else {
        s::prox_pv_many(m, gq.data(), gv.data(), gtau.data(), st, bw, qdd.data(), lambda.data());
        s::prox_pv_batch(iq.data(), iv.data(), itau.data(), st, bw, bqdd.data(), blambda.data());
      }
      for (int j = 0; j < m; ++j) {
        S sq[s::nv + 1], sl[s::nc + 1];
        if (f == 0)
          s::constrained_aba(&gq[std::size_t(j * s::nq)], &gv[std::size_t(j * s::nv)], &gtau[std::size_t(j * s::nv)], st, w, sq, sl);
        else
          s::prox_pv(&gq[std::size_t(j * s::nq)], &gv[std::size_t(j * s::nv)], &gtau[std::size_t(j * s::nv)], st, w, sq, sl);
        for (int k = 0; k < s::nv; ++k) check(qdd[std::size_t(j * s::nv + k)], sq[k]);
        for (int r = 0; r < s::nc; ++r) check(lambda[std::size_t(j * s::nc + r)], sl[r]);
        for (int l = j; l < W; l += m) {
          for (int k = 0; k < s::nv; ++k) check(bqdd[std::size_t(k * W + l)], sq[k]);
          for (int r = 0; r < s::nc; ++r) check(blambda[std::size_t(r * W + l)], sl[r]);
        }
      }
    }
  }
  // The library samples (q, v, qdd, lambda).
  int m = 0;
  if (std::scanf("%d", &m) != 1 || m < 0) return 2;
  std::vector<S> lq(std::size_t(m * s::nq) + 1), lv(std::size_t(m * s::nv) + 1), lqdd(std::size_t(m * s::nv) + 1),
      ll(std::size_t(m * s::nc) + 1);
  for (int t = 0; t < m; ++t) {
    double x = 0;
    for (int k = 0; k < s::nq; ++k) { if (std::scanf("%lf", &x) != 1) return 2; lq[std::size_t(t * s::nq + k)] = S(x); }
    for (int k = 0; k < s::nv; ++k) { if (std::scanf("%lf", &x) != 1) return 2; lv[std::size_t(t * s::nv + k)] = S(x); }
    for (int k = 0; k < s::nv; ++k) { if (std::scanf("%lf", &x) != 1) return 2; lqdd[std::size_t(t * s::nv + k)] = S(x); }
    for (int k = 0; k < s::nc; ++k) { if (std::scanf("%lf", &x) != 1) return 2; ll[std::size_t(t * s::nc + k)] = S(x); }
  }
  std::vector<S> iq(std::size_t(s::nq * W)), iv(std::size_t(s::nv * W)), iqdd(std::size_t(s::nv * W)),
      il(std::size_t(s::nc * W) + 1);
  for (int l = 0; l < W && m > 0; ++l) {
    const int j = l % m;
    for (int k = 0; k < s::nq; ++k) iq[std::size_t(k * W + l)] = lq[std::size_t(j * s::nq + k)];
    for (int k = 0; k < s::nv; ++k) iv[std::size_t(k * W + l)] = lv[std::size_t(j * s::nv + k)];
    for (int k = 0; k < s::nv; ++k) iqdd[std::size_t(k * W + l)] = lqdd[std::size_t(j * s::nv + k)];
    for (int k = 0; k < s::nc; ++k) il[std::size_t(k * W + l)] = ll[std::size_t(j * s::nc + k)];
  }
  [[maybe_unused]] const auto Q = [&](int j) { return &lq[std::size_t(j * s::nq)]; };
  [[maybe_unused]] const auto V = [&](int j) { return &lv[std::size_t(j * s::nv)]; };
  [[maybe_unused]] const auto A = [&](int j) { return &lqdd[std::size_t(j * s::nv)]; };
  [[maybe_unused]] const auto L = [&](int j) { return &ll[std::size_t(j * s::nc)]; };
#if PROXGEN_VERIFY_HAS_INVERSE_DYNAMICS
  library(m, s::nv, [&](int j, S* o) { s::inverse_dynamics(Q(j), V(j), A(j), L(j), w, o); },
          [&](S* o) { s::inverse_dynamics_batch(iq.data(), iv.data(), iqdd.data(), il.data(), bw, o); },
          [&](S* o) { s::inverse_dynamics_many(m, lq.data(), lv.data(), lqdd.data(), ll.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_NONLINEAR_EFFECTS
  library(m, s::nv, [&](int j, S* o) { s::nonlinear_effects(Q(j), V(j), w, o); },
          [&](S* o) { s::nonlinear_effects_batch(iq.data(), iv.data(), bw, o); },
          [&](S* o) { s::nonlinear_effects_many(m, lq.data(), lv.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_MASS_MATRIX
  library(m, s::nv * s::nv, [&](int j, S* o) { s::mass_matrix(Q(j), w, o); },
          [&](S* o) { s::mass_matrix_batch(iq.data(), bw, o); }, [&](S* o) { s::mass_matrix_many(m, lq.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_MASS_MATRIX_INVERSE
  library(m, s::nv * s::nv, [&](int j, S* o) { s::mass_matrix_inverse(Q(j), w, o); },
          [&](S* o) { s::mass_matrix_inverse_batch(iq.data(), bw, o); },
          [&](S* o) { s::mass_matrix_inverse_many(m, lq.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_PLACEMENTS
  library(m, 12 * s::ncons, [&](int j, S* o) { s::constraint_placements(Q(j), w, o); },
          [&](S* o) { s::constraint_placements_batch(iq.data(), bw, o); },
          [&](S* o) { s::constraint_placements_many(m, lq.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_JACOBIAN
  library(m, s::nc * s::nv, [&](int j, S* o) { s::constraint_jacobian(Q(j), w, o); },
          [&](S* o) { s::constraint_jacobian_batch(iq.data(), bw, o); },
          [&](S* o) { s::constraint_jacobian_many(m, lq.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_DRIFT
  library(m, s::nc, [&](int j, S* o) { s::constraint_drift(Q(j), V(j), w, o); },
          [&](S* o) { s::constraint_drift_batch(iq.data(), iv.data(), bw, o); },
          [&](S* o) { s::constraint_drift_many(m, lq.data(), lv.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_DELASSUS
  library(m, s::nc * s::nc, [&](int j, S* o) { s::delassus(Q(j), w, o); },
          [&](S* o) { s::delassus_batch(iq.data(), bw, o); }, [&](S* o) { s::delassus_many(m, lq.data(), bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_DELASSUS_INVERSE
  library(m, s::nc * s::nc, [&](int j, S* o) { s::delassus_inverse(Q(j), s::Settings{}, w, o); },
          [&](S* o) { s::delassus_inverse_batch(iq.data(), s::Settings{}, bw, o); },
          [&](S* o) { s::delassus_inverse_many(m, lq.data(), s::Settings{}, bw, o); });
#endif
#if PROXGEN_VERIFY_HAS_CONSTRAINT_WRENCHES
  library(m, 6 * s::ncons, [&](int j, S* o) { s::constraint_wrenches(Q(j), L(j), w, o); },
          [&](S* o) { s::constraint_wrenches_batch(iq.data(), il.data(), bw, o); },
          [&](S* o) { s::constraint_wrenches_many(m, lq.data(), ll.data(), bw, o); });
#endif
  std::printf("%ld %ld\n", compared, differ);
  return 0;
}
)";

// The driver's defines: one per function the solver holds.
std::string driverDefines(const FunctionSet& functions) {
  std::string out;
  for (const std::string& name : functions.names()) {
    std::string upper = name;
    for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
    out += "#define PROXGEN_VERIFY_HAS_" + upper + " 1\n";
  }
  return out;
}

struct Trial {
  int sample, K;
  double mu;
};

// The System of the options: a URDF and a layout, or one case of a cases file.
System loadVerified(const VerifyOptions& o) {
  System sys = o.cases.empty() ? loadSystem(o.urdf, o.layout) : loadCaseSystem(loadCase(o.cases, o.caseName));
  if (!o.functions.empty()) sys.functions = parseFunctionList(o.functions, "command line", "--functions");
  return sys;
}

// --keep names a folder; anything else there is refused before the work starts.
void checkKeep(const std::string& keep) {
  if (keep.empty()) return;
  struct stat st {};
  if (stat(keep.c_str(), &st) == 0 && !S_ISDIR(st.st_mode))
    fail("command line", "--keep", fmt::format("{} exists and is not a folder", proxgen::quoted(keep)));
}

// A private folder for the solver, the driver and their files: mkdtemp in
// TMPDIR (or /tmp), refused with a message naming it when it is missing or not writable.
fs::path makeTemporaryFolder() {
  const char* env = std::getenv("TMPDIR");
  const std::string base = env && *env ? env : "/tmp";
  std::string pattern = (fs::path(base) / "proxgen-verify-XXXXXX").string();
  if (!mkdtemp(pattern.data()))
    throw Error(fmt::format("verify: cannot create a temporary folder in {} ({}): set TMPDIR to a writable folder",
                            proxgen::quoted(base), std::strerror(errno)));
  return pattern;
}

// The private folder and every file in it, removed at the end (and by the
// interrupt handler, emit/output.hpp, if the run is interrupted).
class Scratch {
 public:
  explicit Scratch(fs::path dir) : dir_(std::move(dir)) { slots_.push_back(emit::registerTemporary(dir_.string())); }
  ~Scratch() {
    std::error_code ec;
    for (const std::string& f : files_) fs::remove(dir_ / f, ec);
    fs::remove(dir_, ec);
    for (int s : slots_) emit::unregisterTemporary(s);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  /// The path of a file of this folder, registered before anything creates it.
  fs::path file(const std::string& name) {
    files_.push_back(name);
    slots_.push_back(emit::registerTemporary((dir_ / name).string()));
    return dir_ / name;
  }
  const fs::path& dir() const { return dir_; }
  const std::vector<std::string>& files() const { return files_; }

 private:
  fs::path dir_;
  std::vector<std::string> files_;
  std::vector<int> slots_;
};

// Copies what verify made into --keep through the one atomic, link-safe writer.
void keepFiles(const Scratch& scratch, const std::string& keep) {
  std::vector<emit::OutputFile> out;
  for (const std::string& f : scratch.files()) {
    std::error_code ec;
    if (!fs::is_regular_file(fs::symlink_status(scratch.dir() / f, ec))) continue;  // not made (a step failed)
    out.push_back({f, slurp(scratch.dir() / f), f == "driver"});
  }
  emit::writeFiles(out, keep);
  fmt::print("kept the generated solver, driver and logs in {}\n", oneLine(keep, 1000));
}

const char* const kSolverName = "proxgen_verify_solver";

int verify(const VerifyOptions& o) {
  checkKeep(o.keep);
  const System sys = loadVerified(o);
  const Model& m = sys.model;
  const bool isFloat = o.scalar == "float";
  if (isFloat) printWarning(floatAccuracyWarning(sys));

  Scratch scratch(makeTemporaryFolder());
  const fs::path hpp = scratch.file(std::string(kSolverName) + ".hpp"), cpp = scratch.file(std::string(kSolverName) + ".cpp"),
                 driverCpp = scratch.file("driver.cpp"), driverObj = scratch.file("driver.o"),
                 solverObj = scratch.file(std::string(kSolverName) + ".o"), driver = scratch.file("driver"),
                 compileLog = scratch.file("compile.log"), input = scratch.file("input.txt"),
                 output = scratch.file("output.txt");
  // Kept on failure too: the files of a failed compile are what one wants to see.
  struct KeepOnExit {
    const Scratch& scratch;
    const std::string& keep;
    bool done = false;
    ~KeepOnExit() {
      if (keep.empty() || done) return;
      try {
        keepFiles(scratch, keep);
      } catch (const std::exception&) {  // the first error is the one reported
      }
    }
  } keepOnExit{scratch, o.keep};

  const auto t0 = std::chrono::steady_clock::now();
  // (generateFiles directly, not generateSolverFiles: the warning is out already)
  emit::SolverFiles generated;
  if (!o.cases.empty()) {
    generated = generateCase(o.cases, o.caseName, kSolverName, emit::parseScalar(o.scalar), nullptr, nullptr, o.functions);
  } else {
    emit::GenerateOptions g;
    g.urdf = o.urdf;
    g.layout = o.layout;
    g.name = kSolverName;
    g.scalar = emit::parseScalar(o.scalar);
    g.functions = o.functions;
    generated = emit::generateFiles(g);
  }
  std::vector<emit::OutputFile> files = emit::solverOutputs(generated);
  // The solver's two files only: the C interface (NAME_c.*) is not what verify
  // compiles, and every file in the scratch folder must be one it registered.
  files.resize(2);
  files.push_back({"driver.cpp", driverDefines(sys.functions) + kDriver});
  // --batch: the batched files and their driver, registered before they are written.
  fs::path batchCpp, batchObj, batchDriverCpp, batchDriverObj, batchDriver, batchOutput;
  if (o.batch != 0) {
    const emit::BatchFiles batch = emit::batchFiles(generated, o.batch);
    scratch.file(batch.headerName);
    batchCpp = scratch.file(batch.sourceName);
    batchObj = scratch.file(std::string(kSolverName) + "_batch.o");
    batchDriverCpp = scratch.file("batch_driver.cpp");
    batchDriverObj = scratch.file("batch_driver.o");
    batchDriver = scratch.file("batch_driver");
    batchOutput = scratch.file("batch_output.txt");
    files.push_back({batch.headerName, batch.header});
    files.push_back({batch.sourceName, batch.source});
    files.push_back({"batch_driver.cpp", driverDefines(sys.functions) + kBatchDriver});
  }
  emit::writeFiles(files, scratch.dir().string());
  const auto t1 = std::chrono::steady_clock::now();
  // Each source to its own object, then the link: every file the compiler
  // writes is one of the scratch folder's registered names (-pipe: no
  // assembler files; -c -o: no objects in TMPDIR), so an interrupt leaves nothing.
  std::vector<std::string> compile = {PROXGEN_CXX_COMPILER, "-std=c++17", "-pipe"};
  for (const std::string& option : solverCompileOptions()) compile.push_back(option);
  // The batched lanes are the scalar solver's bits where no multiply-add is fused in one and not the other.
  if (o.batch != 0) compile.push_back("-ffp-contract=off");
  compile.insert(compile.end(), {"-I", runtimeDir().string(), "-I", scratch.dir().string(), "-c"});
  const auto compileOne = [&](const fs::path& source, const fs::path& object) {
    std::vector<std::string> argv = compile;
    argv.insert(argv.end(), {source.string(), "-o", object.string()});
    return runProcess(argv, compileLog);
  };
  std::vector<std::string> link = {PROXGEN_CXX_COMPILER, "-std=c++17"};
  for (const std::string& option : solverCompileOptions()) link.push_back(option);
  link.insert(link.end(), {driverObj.string(), solverObj.string(), "-o", driver.string()});
  if (compileOne(driverCpp, driverObj) != 0 || compileOne(cpp, solverObj) != 0 || runProcess(link, compileLog) != 0)
    throw Error(fmt::format("verify: the generated solver does not compile ({}): {}", PROXGEN_CXX_COMPILER,
                            firstErrors(slurp(compileLog))));
  if (o.batch != 0) {
    std::vector<std::string> batchLink = {PROXGEN_CXX_COMPILER, "-std=c++17"};
    for (const std::string& option : solverCompileOptions()) batchLink.push_back(option);
    batchLink.insert(batchLink.end(),
                     {batchDriverObj.string(), batchObj.string(), solverObj.string(), "-o", batchDriver.string()});
    if (compileOne(batchDriverCpp, batchDriverObj) != 0 || compileOne(batchCpp, batchObj) != 0 ||
        runProcess(batchLink, compileLog) != 0)
      throw Error(fmt::format("verify: the batched solver does not compile ({}): {}", PROXGEN_CXX_COMPILER,
                              firstErrors(slurp(compileLog))));
  }
  const auto t2 = std::chrono::steady_clock::now();

  // Trials: every sample at K = 1, 2, 3 and converged, at the layout's mu and at
  // mu = 100 (where one iteration too many or too few is visible). A float
  // solver sees its inputs rounded to float; so does the generic side.
  std::mt19937 rng(o.seed);
  std::vector<State> states;
  for (int s = 0; s < o.samples; ++s) states.push_back(verify::roundedToScalar(randomState(m, rng), isFloat));
  std::vector<Trial> trials;
  const bool solvers = sys.functions.has(Function::ConstrainedAba) && sys.functions.has(Function::ProxPv);
  for (int s = 0; s < o.samples && solvers; ++s)
    for (double mu : {sys.mu, 100.0})
      for (int K : {1, 2, 3, o.converged}) trials.push_back({s, K, mu});
  // The joint-space functions' extra inputs: qdd ~ N(0, 1), lambda ~ 10 N(0, 1), per state.
  bool library = false;  // any function beyond the two solvers
  for (Function f : allFunctions())
    library = library || (sys.functions.has(f) && f != Function::ConstrainedAba && f != Function::ProxPv);
  std::vector<verify::LibraryAnswer> libraryIn;
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto rounded = [&](double x) { return isFloat ? double(float(x)) : x; };
  for (int s = 0; s < o.samples && library; ++s) {
    verify::LibraryAnswer a;
    a.qdd = VecX(m.nv);
    a.lambda = VecX(sys.nc);
    for (int k = 0; k < m.nv; ++k) a.qdd[k] = rounded(normal(rng));
    for (int k = 0; k < sys.nc; ++k) a.lambda[k] = rounded(10.0 * normal(rng));
    libraryIn.push_back(a);
  }
  {
    std::ofstream in(input);
    in << trials.size() << "\n";
    const auto put = [&](const VecX& x) {
      for (int k = 0; k < x.size(); ++k) in << fmt::format("{}\n", x[k]);
    };
    for (const Trial& t : trials) {
      put(states[t.sample].q);
      put(states[t.sample].v);
      put(states[t.sample].tau);
      in << fmt::format("{} {}\n", t.mu, t.K);
    }
    in << libraryIn.size() << "\n";
    for (std::size_t s = 0; s < libraryIn.size(); ++s) {
      put(states[s].q);
      put(states[s].v);
      put(libraryIn[s].qdd);
      put(libraryIn[s].lambda);
    }
    if (!in) throw Error(fmt::format("verify: {}: cannot be written", proxgen::quoted(input.string())));
  }
  if (runProcess({driver.string()}, output, input) != 0)
    throw Error(fmt::format("verify: the generated solver's driver failed: {}", firstErrors(slurp(output))));
  long batchCompared = 0, batchDiffer = 0;
  if (o.batch != 0) {
    if (runProcess({batchDriver.string()}, batchOutput, input) != 0)
      throw Error(fmt::format("verify: the batched solver's driver failed: {}", firstErrors(slurp(batchOutput))));
    std::istringstream b(slurp(batchOutput));
    if (!(b >> batchCompared >> batchDiffer) || batchCompared <= 0)
      throw Error("verify: the batched solver's driver printed no comparison");
  }

  std::istringstream out(slurp(output));
  out.imbue(std::locale::classic());
  // The driver prints with %.17g: "inf" and "nan" read back as failures, so
  // they are read as text and named.
  const auto read = [&](int n, const char* what, const Trial& t) {
    VecX x(n);
    for (int k = 0; k < n; ++k) {
      std::string word;
      if (!(out >> word)) throw Error("verify: the driver's output is short");
      char* end = nullptr;
      x[k] = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0')
        throw Error(fmt::format("verify: the driver printed {} for {}", proxgen::quoted(word), what));
      if (!std::isfinite(x[k]))
        throw Error(fmt::format("verify: the generated {}[{}] is not finite ({}) at sample {}, mu {}, K {}: the solver "
                                "overflowed",
                                what, k, word, t.sample, t.mu, t.K));
    }
    return x;
  };
  Data d(sys), dense(sys);
  std::vector<verify::Conditioning> conditioning;
  for (const State& s : states) conditioning.push_back(verify::conditioningAt(sys, dense, s, isFloat));
  // Largest error and largest error / bound (over the trials, separately) per
  // quantity, keyed by "algorithm quantity K".
  struct Worst {
    std::string key;
    double error = 0, ratio = 0;
  };
  std::vector<Worst> worst;
  const auto record = [&](const std::string& key, double e, double bound) {
    const double ratio = e / (o.tolerance > 0 ? o.tolerance : bound);
    for (Worst& w : worst)
      if (w.key == key) {
        w.error = std::max(w.error, e);
        w.ratio = std::max(w.ratio, ratio);
        return;
      }
    worst.push_back({key, e, ratio});
  };
  for (const Trial& t : trials) {
    const State& s = states[t.sample];
    const std::string K = t.K == o.converged ? fmt::format("K={} (converged)", t.K) : fmt::format("K={}", t.K);
    verify::GeneratedAnswer gen;
    gen.cabaQdd = read(m.nv, "constrained_aba qdd", t);
    gen.cabaLambda = read(sys.nc, "constrained_aba lambda", t);
    gen.pvQdd = read(m.nv, "prox_pv qdd", t);
    gen.pvLambda = read(sys.nc, "prox_pv lambda", t);
    const verify::Bounds bounds = verify::boundsAt(conditioning[std::size_t(t.sample)], t.mu);
    const verify::Comparison c = verify::compareWithGeneric(sys, d, conditioning[std::size_t(t.sample)], bounds, s, t.K, gen);
    for (const verify::Compared& x : c.item) {
      if (!x.finite)
        throw Error(fmt::format("verify: the generic {} is not finite at sample {}, mu {}, K {}: the state overflows "
                                "double",
                                x.what, t.sample, t.mu, t.K));
      record(fmt::format("{:<22} {}", x.what, K), x.error, x.bound);
    }
  }

  // The joint-space functions, sample by sample (the driver's order).
  for (std::size_t s = 0; s < libraryIn.size(); ++s) {
    verify::LibraryAnswer gen = libraryIn[s];
    const Trial at{int(s), 0, 0.0};
    if (sys.functions.has(Function::InverseDynamics)) gen.tau = read(m.nv, "inverse_dynamics tau", at);
    if (sys.functions.has(Function::NonlinearEffects)) gen.h = read(m.nv, "nonlinear_effects h", at);
    const auto square = [&](const char* what) {
      const VecX x = read(m.nv * m.nv, what, at);
      MatX M(m.nv, m.nv);
      for (int r = 0; r < m.nv; ++r)
        for (int c = 0; c < m.nv; ++c) M(r, c) = x[r * m.nv + c];  // row-major
      return M;
    };
    if (sys.functions.has(Function::MassMatrix)) gen.M = square("mass_matrix M");
    if (sys.functions.has(Function::MassMatrixInverse)) gen.Minv = square("mass_matrix_inverse");
    verify::ConstraintAnswer cons;  // row-major, as the driver prints them
    const int ncons = int(sys.constraints.size());
    if (sys.functions.has(Function::ConstraintPlacements)) cons.X = read(12 * ncons, "constraint_placements", at);
    if (sys.functions.has(Function::ConstraintJacobian)) cons.J = read(sys.nc * m.nv, "constraint_jacobian", at);
    if (sys.functions.has(Function::ConstraintDrift)) cons.gamma = read(sys.nc, "constraint_drift", at);
    if (sys.functions.has(Function::Delassus)) cons.G = read(sys.nc * sys.nc, "delassus", at);
    if (sys.functions.has(Function::DelassusInverse)) cons.Ginv = read(sys.nc * sys.nc, "delassus_inverse", at);
    if (sys.functions.has(Function::ConstraintWrenches)) cons.W = read(6 * ncons, "constraint_wrenches", at);
    cons.lambda = libraryIn[s].lambda;
    cons.mu = sys.mu;
    // The derivatives (docs/derivatives.md), forward and constrained at tau = the sample's qdd.
    verify::DerivativeAnswer der;
    der.qdd = der.tau = libraryIn[s].qdd;
    der.lambda = libraryIn[s].lambda;
    der.mu = sys.mu;
    der.K = sys.iterations;
    const auto matrix = [&](int rows, const char* what) {
      const VecX x = read(rows * m.nv, what, at);
      MatX A(rows, m.nv);
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < m.nv; ++c) A(r, c) = x[r * m.nv + c];  // row-major
      return A;
    };
    if (sys.functions.has(Function::InverseDynamicsDerivatives)) {
      der.dtau_dq = matrix(m.nv, "inverse_dynamics_derivatives dtau_dq");
      der.dtau_dv = matrix(m.nv, "inverse_dynamics_derivatives dtau_dv");
    }
    if (sys.functions.has(Function::ForwardDynamicsDerivatives)) {
      der.fQdd = read(m.nv, "forward_dynamics_derivatives qdd", at);
      der.fDq = matrix(m.nv, "forward_dynamics_derivatives dqdd_dq");
      der.fDv = matrix(m.nv, "forward_dynamics_derivatives dqdd_dv");
      der.fDtau = matrix(m.nv, "forward_dynamics_derivatives dqdd_dtau");
    }
    if (sys.functions.has(Function::ConstrainedDynamicsDerivatives)) {
      der.cQdd = read(m.nv, "constrained_dynamics_derivatives qdd", at);
      der.cLambda = read(sys.nc, "constrained_dynamics_derivatives lambda", at);
      der.cDq = matrix(m.nv, "constrained_dynamics_derivatives dqdd_dq");
      der.cDv = matrix(m.nv, "constrained_dynamics_derivatives dqdd_dv");
      der.cDtau = matrix(m.nv, "constrained_dynamics_derivatives dqdd_dtau");
      der.cLq = matrix(sys.nc, "constrained_dynamics_derivatives dlambda_dq");
      der.cLv = matrix(sys.nc, "constrained_dynamics_derivatives dlambda_dv");
      der.cLtau = matrix(sys.nc, "constrained_dynamics_derivatives dlambda_dtau");
    }
    std::vector<verify::Compared> items = verify::compareLibraryWithGeneric(sys, d, conditioning[s], states[s], gen);
    for (const verify::Compared& x : verify::compareConstraintFunctions(sys, d, conditioning[s], states[s], cons))
      items.push_back(x);
    for (const verify::Compared& x : verify::compareDerivatives(sys, d, conditioning[s], states[s], der))
      items.push_back(x);
    for (const verify::Compared& x : items) {
      if (!x.finite) throw Error(fmt::format("verify: the generic {} is not finite at sample {}", x.what, s));
      record(x.what, x.error, x.bound);
    }
  }

  const double secs = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); }(t0, t1);
  const double csecs = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); }(t1, t2);
  const std::string what = o.cases.empty() ? o.urdf : fmt::format("case {} of {}", o.caseName, o.cases);
  fmt::print("proxgen verify: {} ({} bodies, nq = {}, nv = {}, nc = {}), scalar {}\n", oneLine(what), m.numBodies() - 1,
             m.nq, m.nv, sys.nc, o.scalar);
  fmt::print("generated in {:.2f} s, compiled in {:.1f} s; {} random states x mu in {{{:g}, 100}}\n", secs, csecs,
             o.samples, sys.mu);
  fmt::print("largest relative error vs the generic solver (max|gen - generic| / max(1, max|generic|)) and largest "
             "error / bound, the bound {}:\n",
             o.tolerance > 0 ? fmt::format("--tolerance {:g}", o.tolerance)
                             : std::string("c n u kappa at each state (verify/compare.cpp)"));
  bool ok = true;
  for (const Worst& w : worst) {
    const bool pass = w.ratio <= 1;
    ok = ok && pass;
    fmt::print("  {:<40} {:10.3e}  {:8.2e}  {}\n", w.key, w.error, w.ratio, pass ? "ok" : "FAIL");
  }
  if (o.batch != 0) {
    const bool pass = batchDiffer == 0;
    ok = ok && pass;
    fmt::print("  batched (--batch {}) vs scalar, bit for bit: {} answers, {} differ  {}\n", o.batch, batchCompared,
               batchDiffer, pass ? "ok" : "FAIL");
  }
  fmt::print("{}: {}\n", ok ? "PASSED" : "FAILED",
             o.tolerance > 0 ? fmt::format("tolerance {:g}", o.tolerance) : std::string("bounds c n u kappa"));
  if (!o.keep.empty()) {
    keepOnExit.done = true;
    keepFiles(scratch, o.keep);
  }
  return ok ? 0 : 1;
}

}  // namespace

void addVerify(CLI::App& app) {
  auto o = std::make_shared<VerifyOptions>();
  auto* cmd = app.add_subcommand("verify", "generate, compile and compare a solver with the generic solvers");
  cmd->add_option("urdf", o->urdf, "robot URDF");
  cmd->add_option("--layout", o->layout, "constraint layout (YAML)");
  cmd->add_option("--cases", o->cases, "a cases file (cases.yaml), instead of URDF and layout");
  cmd->add_option("--case", o->caseName, "the case of --cases to verify");
  cmd->add_option("--samples", o->samples, "random states")->check(CLI::Range(1, 100000));
  cmd->add_option("--scalar", o->scalar, "double or float")->check(CLI::IsMember({"double", "float"}));
  cmd->add_option("--tolerance", o->tolerance,
                  "largest relative error accepted (default: the bound from the state's conditioning, c n u kappa)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seed", o->seed, "random seed");
  cmd->add_option("--keep", o->keep, "copy the generated solver, driver and logs to this folder");
  cmd->add_option("--functions", o->functions,
                  "the functions to generate and compare, a,b,... or all (default: the layout's functions:)");
  CLI::Option* batchOption = cmd->add_option("--batch", o->batchText,
                  "also generate the batched solvers over W lanes (2, 4, 8 or 16) and compare every lane with the "
                  "scalar solver (docs/batch.md)")
      ->type_name("W");
  cmd->callback([o, batchOption] {
    checkRobotOptions("verify", o->urdf, o->layout, o->cases, o->caseName);
    o->batch = emit::parseBatchWidth(o->batchText, batchOption->count() > 0);
    const int rc = verify(*o);
    if (rc != 0) std::exit(rc);
  });
}

}  // namespace proxgen::cli
