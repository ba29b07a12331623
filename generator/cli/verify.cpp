// proxgen verify: generate a solver into a temporary folder, compile it with the
// compiler proxgen was built with, run it on random states and compare qdd and
// the multipliers with the generic solvers at K = 1, 2, 3 and at convergence.
// This is what a user runs on their own robot before trusting a generated solver.
//   proxgen verify robot.urdf --layout layout.yaml [--samples N]
//   proxgen verify --cases cases.yaml --case NAME [--samples N]
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/prox_pv.hpp"
#include "cli/commands.hpp"
#include "model/cases.hpp"
#include "model/error.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"

namespace fs = std::filesystem;

namespace proxgen::cli {
namespace {

struct VerifyOptions {
  std::string urdf, layout, cases, caseName, scalar = "double", keep;
  int samples = 20;
  unsigned seed = 1;
  double tolerance = 0;  // 0: the scalar's default
  int converged = 100;
};

// Runs argv (no shell), stdout+stderr to `log`; returns the exit status.
int runProcess(const std::vector<std::string>& argv, const fs::path& log, const fs::path& in = {}) {
  const pid_t pid = fork();
  if (pid < 0) throw Error("verify: fork failed");
  if (pid == 0) {
    if (!in.empty() && !std::freopen(in.c_str(), "r", stdin)) _exit(126);
    if (!std::freopen(log.c_str(), "w", stdout)) _exit(126);
    if (dup2(fileno(stdout), fileno(stderr)) < 0) _exit(126);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
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
// qdd and lambda of constrained_aba then prox_pv, one number per line.
constexpr const char* kDriver = R"(// proxgen verify driver (temporary)
#include <cstdio>
#include "proxgen_verify_solver.hpp"
namespace s = proxgen_verify_solver;
static s::Workspace w;
int main() {
  int n = 0;
  if (std::scanf("%d", &n) != 1) return 2;
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
  return 0;
}
)";

struct Trial {
  int sample, K;
  double mu;
};

double relErr(const VecX& a, const VecX& b) {
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

// The System of the options: a URDF and a layout, or one case of a cases file.
System loadVerified(const VerifyOptions& o) {
  return o.cases.empty() ? loadSystem(o.urdf, o.layout) : loadCaseSystem(loadCase(o.cases, o.caseName));
}

int verify(const VerifyOptions& o) {
  const System sys = loadVerified(o);
  const Model& m = sys.model;
  // Default tolerances: the generated and the generic solver do the same
  // operations in a different order, so they differ by about cond * eps. A wrong
  // term gives errors of order 1, so a bound far above round-off loses nothing.
  const double tol = o.tolerance > 0 ? o.tolerance : (o.scalar == "float" ? 1e-2 : 1e-8);

  const fs::path tmp = [] {
    std::string pattern = (fs::temp_directory_path() / "proxgen-verify-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw Error("verify: cannot create a temporary folder");
    return fs::path(pattern);
  }();
  struct Cleanup {
    fs::path dir;
    bool keep;
    ~Cleanup() {
      std::error_code ec;
      if (!keep) fs::remove_all(dir, ec);
    }
  } cleanup{tmp, !o.keep.empty()};

  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("verify: cannot find the proxgen executable");
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> generate = {self.string(), "generate"};
  if (o.cases.empty())
    generate.insert(generate.end(), {o.urdf, "--layout", o.layout});
  else
    generate.insert(generate.end(), {"--cases", o.cases, "--case", o.caseName});
  generate.insert(generate.end(), {"--out", tmp.string(), "--name", "proxgen_verify_solver", "--scalar", o.scalar});
  if (runProcess(generate, tmp / "generate.log") != 0)
    throw Error(fmt::format("verify: generation failed:\n{}", slurp(tmp / "generate.log")));
  const auto t1 = std::chrono::steady_clock::now();
  std::ofstream(tmp / "driver.cpp") << kDriver;
  if (runProcess({PROXGEN_CXX_COMPILER, "-std=c++17", "-O2", "-fno-exceptions", "-fno-rtti", "-I", runtimeDir().string(),
                  "-I", tmp.string(), (tmp / "driver.cpp").string(), (tmp / "proxgen_verify_solver.cpp").string(),
                  "-o", (tmp / "driver").string()},
                 tmp / "compile.log") != 0)
    throw Error(fmt::format("verify: the generated solver does not compile:\n{}", slurp(tmp / "compile.log")));
  const auto t2 = std::chrono::steady_clock::now();

  // Trials: every sample at K = 1, 2, 3 and converged, at the layout's mu and at
  // mu = 100 (where one iteration too many or too few is visible).
  std::mt19937 rng(o.seed);
  std::vector<State> states;
  for (int s = 0; s < o.samples; ++s) states.push_back(randomState(m, rng));
  std::vector<Trial> trials;
  for (int s = 0; s < o.samples; ++s)
    for (double mu : {sys.mu, 100.0})
      for (int K : {1, 2, 3, o.converged}) trials.push_back({s, K, mu});
  {
    std::ofstream in(tmp / "input.txt");
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
  }
  if (runProcess({(tmp / "driver").string()}, tmp / "output.txt", tmp / "input.txt") != 0)
    throw Error(fmt::format("verify: the generated solver's driver failed:\n{}", slurp(tmp / "output.txt")));

  std::istringstream out(slurp(tmp / "output.txt"));
  out.imbue(std::locale::classic());
  const auto read = [&](int n) {
    VecX x(n);
    for (int k = 0; k < n; ++k)
      if (!(out >> x[k])) throw Error("verify: the driver's output is short");
    return x;
  };
  Data d(sys);
  // Largest error per quantity, keyed by "algorithm quantity K".
  std::vector<std::pair<std::string, double>> worst;
  const auto record = [&](const std::string& key, double e) {
    for (auto& w : worst)
      if (w.first == key) {
        w.second = std::max(w.second, e);
        return;
      }
    worst.push_back({key, e});
  };
  for (const Trial& t : trials) {
    const State& s = states[t.sample];
    const std::string K = t.K == o.converged ? fmt::format("K={} (converged)", t.K) : fmt::format("K={}", t.K);
    const VecX gq = read(m.nv), gl = read(sys.nc);
    constrainedAba(sys, d, s.q, s.v, s.tau, t.mu, t.K);
    record(fmt::format("constrained_aba qdd    {}", K), relErr(gq, d.qdd));
    record(fmt::format("constrained_aba lambda {}", K), relErr(gl, d.lambda));
    const VecX pq = read(m.nv), pl = read(sys.nc);
    proxPv(sys, d, s.q, s.v, s.tau, t.mu, t.K);
    record(fmt::format("prox_pv         qdd    {}", K), relErr(pq, d.qdd));
    record(fmt::format("prox_pv         lambda {}", K), relErr(pl, d.lambda));
  }

  const double secs = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); }(t0, t1);
  const double csecs = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); }(t1, t2);
  const std::string what = o.cases.empty() ? o.urdf : fmt::format("case {} of {}", o.caseName, o.cases);
  fmt::print("proxgen verify: {} ({} bodies, nq = {}, nv = {}, nc = {}), scalar {}\n", what, m.numBodies() - 1, m.nq,
             m.nv, sys.nc, o.scalar);
  fmt::print("generated in {:.2f} s, compiled (-O2) in {:.1f} s; {} random states x mu in {{{:g}, 100}}\n", secs, csecs,
             o.samples, sys.mu);
  fmt::print("largest relative error vs the generic solver (max|gen - generic| / max(1, max|generic|)):\n");
  bool ok = true;
  for (const auto& [key, e] : worst) {
    const bool pass = e <= tol;
    ok = ok && pass;
    fmt::print("  {:<40} {:10.3e}  {}\n", key, e, pass ? "ok" : "FAIL");
  }
  fmt::print("{}: tolerance {:g}\n", ok ? "PASSED" : "FAILED", tol);
  if (!o.keep.empty()) {
    fs::create_directories(o.keep);
    for (const auto& f : fs::directory_iterator(tmp)) fs::copy(f.path(), fs::path(o.keep) / f.path().filename(), fs::copy_options::overwrite_existing | fs::copy_options::recursive);
    fmt::print("kept the generated solver, driver and logs in {}\n", o.keep);
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
  cmd->add_option("--tolerance", o->tolerance, "largest relative error accepted (default 1e-8 double, 1e-2 float)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seed", o->seed, "random seed");
  cmd->add_option("--keep", o->keep, "copy the generated solver, driver and logs to this folder");
  cmd->callback([o] {
    checkRobotOptions("verify", o->urdf, o->layout, o->cases, o->caseName);
    const int rc = verify(*o);
    if (rc != 0) std::exit(rc);
  });
}

}  // namespace proxgen::cli
