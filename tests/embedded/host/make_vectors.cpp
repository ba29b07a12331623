// proxgen_make_vectors: the host half of the embedded solver tests (docs/embedded.md).
//
// For one case it writes, into --out DIR:
//   double/NAME.{hpp,cpp}, float/NAME.{hpp,cpp}  the generated solvers, through the same library
//       call as `proxgen generate URDF --layout LAYOUT --out DIR/<scalar> --name NAME --scalar <scalar>`
//       (emit::generateFiles: byte-identical files)
//   layout.yaml        (shared cases only) the case's keys of cases.yaml, as a layout file
//   vectors_NAME.cpp   a few fixed states and the answers of the generic solvers (constrainedAba,
//       proxPv) in double at K = 3 and K = 100 (converged) over a sweep of mu, with what the
//       firmware's tolerance is made of (tests/embedded/solver/solver_main.cpp): the round-off
//       bound of these double answers (tests/numerics.hpp, roundoffBounds), the Jacobi-scaled
//       condition numbers of M and G, and the lightest body on the constraint support.
// The cross build (tests/embedded/CMakeLists.txt) compiles them into one firmware per case and
// scalar; the firmware (tests/embedded/solver/solver_main.cpp) runs the solver and compares.
//
//   proxgen_make_vectors --name NAME --out DIR (--urdf URDF --layout LAYOUT | --cases CASES.yaml)
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/dense_reference.hpp"
#include "algorithms/prox_pv.hpp"
#include "emit/generate.hpp"
#include "cases/cases.hpp"
#include "model/error.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "numerics.hpp"

namespace fs = std::filesystem;
using namespace proxgen;

namespace {

constexpr int kStates = 3;
constexpr unsigned kSeed = 20261125;
constexpr int kConverged = 100;            // "at convergence": the tests' and verify's choice
const std::vector<int> kIterations = {3, kConverged};
// mu sweep for the float-accuracy table; the layout's own mu is added if it is not in it.
const std::vector<double> kMuSweep = {1e2, 1e3, 1e4, 1e5, 1e6};

struct Inputs {
  std::string urdf, layout;
};

// Writes through a temporary file and a rename, and leaves an identical file untouched, so the
// cross build recompiles only what changed.
void writeText(const fs::path& path, const std::string& text) {
  {
    std::ifstream in(path, std::ios::binary);
    const std::string old((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in && old == text) return;
  }
  const fs::path tmp = path.string() + ".tmp";
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw Error(fmt::format("{}: cannot be written", tmp.string()));
  fs::rename(tmp, path);
}

// The case's item of cases.yaml without `name` and `model` is a layout (as loadCases reads it).
Inputs caseInputs(const std::string& casesPath, const std::string& name, const fs::path& outDir) {
  const YAML::Node root = YAML::LoadFile(casesPath);
  for (const Case& c : loadCases(casesPath)) {
    if (c.name != name) continue;
    for (const YAML::Node& item : root["cases"]) {
      if (item["name"].as<std::string>() != name) continue;
      YAML::Node layout = YAML::Clone(item);
      layout.remove("name");
      layout.remove("model");
      YAML::Emitter e;
      e << layout;
      const fs::path path = outDir / "layout.yaml";
      writeText(path, fmt::format("# Case {} of {} (written by proxgen_make_vectors)\n{}\n", name, casesPath,
                                  e.c_str()));
      return {c.urdfPath, path.string()};
    }
  }
  throw Error(fmt::format("{}: no case {}", casesPath, quoted(name)));
}

void generateSolvers(const Inputs& in, const std::string& name, const fs::path& outDir) {
  for (const char* scalar : {"double", "float"}) {
    emit::GenerateOptions g;
    g.urdf = in.urdf;
    g.layout = in.layout;
    g.name = name;
    g.scalar = emit::parseScalar(scalar);
    const emit::SolverFiles files = emit::generateFiles(g);
    fs::create_directories(outDir / scalar);
    writeText(outDir / scalar / files.headerName, files.header);
    writeText(outDir / scalar / files.sourceName, files.source);
  }
}

/// The lightest body with mass on the constraint support: constrainedABA adds the penalty
/// mu K^T K (mu is a mass) to the articulated inertias of these bodies, so a float keeps this
/// body's own inertia only to about u * mu / m (docs/embedded.md, "Float accuracy"). The same
/// choice as the warning of `proxgen check` (generator/cli/check.cpp).
int lightestSupportBody(const System& sys) {
  int best = -1;
  for (int b : sys.supportBodies()) {
    const double m = sys.model.bodies[std::size_t(b)].inertia.mass;
    if (b > 0 && m > 0 && (best < 0 || m < sys.model.bodies[std::size_t(best)].inertia.mass)) best = b;
  }
  return best;
}

struct Tolerance {
  double reference;     // the double answer's round-off bound / eps (primal + dual of numerics.hpp)
  double conditioning;  // kappa_s(M) + kappa_s(G), Jacobi-scaled (numerics.hpp, scaledCondition)
};

Tolerance tolerance(const System& sys, const State& s, double mu) {
  const DenseProblem p = assembleDense(sys, s.q, s.v, s.tau);
  const test::Bounds b = test::roundoffBounds(p, mu);
  const MatX G = p.J * p.M.llt().solve(p.J.transpose());
  return {(b.primal + b.dual) / test::kEps, test::scaledCondition(p.M) + test::scaledCondition(G)};
}

// URDF names reach the vectors file only through this: printable ASCII without quotes or
// backslashes, the rest replaced by '?', so no name can break out of a string or a comment.
std::string safeText(const std::string& s) {
  std::string out;
  for (char c : s) out += (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') ? c : '?';
  return out;
}

// Literals readable by both builds: PROXGEN_R(x) appends `f` in a float firmware, so each value
// is rounded once, from 17 significant digits, to the firmware's scalar.
std::string literal(double x) {
  const std::string digits = fmt::format("{:.16e}", std::abs(x));
  return fmt::format("{}PROXGEN_R({})", std::signbit(x) ? "-" : "", digits);
}

std::string array(const std::string& name, const std::vector<double>& xs) {
  std::string out = fmt::format("const Real {}[] = {{", name);
  for (std::size_t k = 0; k < xs.size(); ++k) out += (k % 4 == 0 ? "\n    " : " ") + literal(xs[k]) + ",";
  if (xs.empty()) out += "\n    PROXGEN_R(0.0)";  // no zero-size arrays
  return out + "\n};\n";
}

void append(std::vector<double>& out, const VecX& x) {
  for (int k = 0; k < x.size(); ++k) out.push_back(x[k]);
}

std::string vectorsSource(const System& sys, const std::string& name, const Inputs& in) {
  const Model& m = sys.model;
  std::mt19937 rng(kSeed);
  std::vector<State> states;
  for (int s = 0; s < kStates; ++s) states.push_back(randomState(m, rng));

  std::vector<double> mus = kMuSweep;
  if (std::find(mus.begin(), mus.end(), sys.mu) == mus.end()) mus.push_back(sys.mu);
  std::sort(mus.begin(), mus.end());

  Data d(sys);
  std::vector<double> q, v, tau, qdd, lambda;
  std::string results;
  int count = 0;
  for (const State& s : states) {
    append(q, s.q);
    append(v, s.v);
    append(tau, s.tau);
  }
  for (int si = 0; si < kStates; ++si) {
    const State& s = states[std::size_t(si)];
    for (double mu : mus) {
      const Tolerance tol = tolerance(sys, s, mu);
      for (int K : kIterations)
        for (int alg = 0; alg < 2; ++alg) {
          if (alg == 0)
            constrainedAba(sys, d, s.q, s.v, s.tau, mu, K);
          else
            proxPv(sys, d, s.q, s.v, s.tau, mu, K);
          results += fmt::format("    {{{}, {}, {}, {}, {}, {}, qdd + {}, lambda + {}}},\n", si,
                                 alg == 0 ? "Algorithm::constrained_aba" : "Algorithm::prox_pv", literal(mu), K,
                                 literal(tol.reference), literal(tol.conditioning), qdd.size(), lambda.size());
          append(qdd, d.qdd);
          append(lambda, d.lambda);
          ++count;
        }
    }
  }

  const int light = lightestSupportBody(sys);
  const double lightMass = light > 0 ? m.bodies[std::size_t(light)].inertia.mass : 0.0;
  const std::string lightName = light > 0 ? safeText(m.bodies[std::size_t(light)].link) : std::string("-");
  std::string out = fmt::format(
      "// Generated by proxgen_make_vectors (tests/embedded/host/make_vectors.cpp), do not edit.\n"
      "// Case {}: robot '{}' ({}), layout {}.\n"
      "// {} random states (proxgen::randomState, seed {}); references from the generic solvers\n"
      "// (constrainedAba, proxPv) in double on the host at K = 3 and {} over a sweep of mu.\n"
      "#include \"proxgen_vectors.hpp\"\n\n"
      "namespace proxgen_vectors {{\nnamespace {{\n\n",
      name, safeText(m.name), safeText(fs::path(in.urdf).filename().string()),
      safeText(fs::path(in.layout).filename().string()), kStates, kSeed,
      kConverged);
  out += array("q", q) + array("v", v) + array("tau", tau) + array("qdd", qdd) + array("lambda", lambda);
  out += "\nconst Result results[] = {\n    // state, algorithm, mu, K, reference round-off / eps, kappa_s(M) + kappa_s(G), qdd, lambda\n" + results +
         "};\n\n}  // namespace\n\n";
  out += fmt::format(
      "extern const Case test_case = {{\n"
      "    \"{}\", {}, {}, {},\n"
      "    {}, // layout mu\n"
      "    {}, \"{}\", // lightest support body: mass (kg), link\n"
      "    {}, q, v, tau,\n"
      "    {}, results}};\n\n}}  // namespace proxgen_vectors\n",
      name, m.nq, m.nv, sys.nc, literal(sys.mu), literal(lightMass), lightName, kStates, count);
  return out;
}

void run(const std::string& name, const std::string& outDir, const Inputs& given, const std::string& cases) {
  const fs::path dir(outDir);
  fs::create_directories(dir);
  const Inputs in = cases.empty() ? given : caseInputs(cases, name, dir);
  generateSolvers(in, name, dir);
  const System sys = loadSystem(in.urdf, in.layout);
  writeText(dir / fmt::format("vectors_{}.cpp", name), vectorsSource(sys, name, in));
  std::ofstream(dir / "stamp") << name << "\n";  // the build's record that this case is done
  std::printf("proxgen_make_vectors: %s: nq %d nv %d nc %d -> %s\n", name.c_str(), sys.model.nq, sys.model.nv, sys.nc,
              outDir.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"solvers and test vectors of one case for the embedded tests"};
  std::string name, out, cases;
  Inputs in;
  app.add_option("--name", name, "case name: solver namespace and file stem")->required();
  app.add_option("--out", out, "output folder")->required();
  auto* urdf = app.add_option("--urdf", in.urdf, "robot URDF (with --layout)");
  auto* layout = app.add_option("--layout", in.layout, "constraint layout (with --urdf)");
  auto* casesOpt = app.add_option("--cases", cases, "cases.yaml: take URDF and layout of case --name from it");
  urdf->needs(layout);
  layout->needs(urdf);
  casesOpt->excludes(urdf)->excludes(layout);
  CLI11_PARSE(app, argc, argv);
  // The name becomes the solver's namespace and file stem as given (the firmware build uses it
  // as both), so it must already be an identifier.
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') ||
      !std::all_of(name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; })) {
    std::fprintf(stderr, "proxgen_make_vectors: --name %s is not a C++ identifier\n", name.c_str());
    return 2;
  }
  if (cases.empty() && in.urdf.empty()) {
    std::fprintf(stderr, "proxgen_make_vectors: give --urdf and --layout, or --cases\n");
    return 2;
  }
  try {
    run(name, out, in, cases);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "proxgen_make_vectors: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
