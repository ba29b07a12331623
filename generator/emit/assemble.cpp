#include "emit/assemble.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>
#include <utility>

#include "emit/identifiers.hpp"

namespace proxgen::emit {
namespace {

// The file skeletons, compiled in (an installed proxgen needs no source tree).
const char* const kBannerTemplate =
#include "../../templates/banner.tpl"
    ;
const char* const kHeaderTemplate =
#include "../../templates/solver.hpp.tpl"
    ;
const char* const kSourceTemplate =
#include "../../templates/solver.cpp.tpl"
    ;

std::string scalarName(ScalarType t) { return t == ScalarType::Float ? "float" : "double"; }

// The functions of the bodies off the constraint support; none when every
// body is on it (no empty functions).
std::string freeBodies(const SolverTexts& texts) {
  if (texts.eliminateFree.empty() && texts.accelerateFree.empty()) return "";
  return fmt::format(
      "// Articulated-body elimination of the bodies off the constraint support\n"
      "// (no constraint below them): the same in both algorithms.\n"
      "void eliminate_free_bodies(const Scalar* tau, Workspace& w) noexcept {{\n{}}}\n\n"
      "// Accelerations of the bodies off the support, once their ancestors are final.\n"
      "void accelerate_free_bodies(Workspace& w) noexcept {{\n{}}}\n\n",
      texts.eliminateFree, texts.accelerateFree);
}

// "a + b K" (b = 0: "a").
std::string affine(long once, long perK) {
  if (perK == 0) return fmt::format("{}", once);
  return fmt::format("{} + {} K", once, perK);
}

// One entry point's line of the banner's operation count (docs/emitter.md).
std::string opLine(const std::string& name, const OpCount& n, int K) {
  const Ops& a = n.once;
  const Ops& b = n.perK;
  return fmt::format(
      "//   {}: {} (= {} at K = {})\n"
      "//     add/sub {}, mul {}, div {}, neg {}, sqrt {}, sincos {}, log6 {}\n",
      name, affine(a.total(), b.total()), n.at(K).total(), K, affine(a.add, b.add), affine(a.mul, b.mul),
      affine(a.div, b.div), affine(a.neg, b.neg), affine(a.sqrt, b.sqrt), affine(a.sincos, b.sincos),
      affine(a.log6, b.log6));
}

// The names and slots of the header (docs/design.md, "Names in the generated
// files"): string arrays of the raw names, slot arrays, and an index per joint
// and per constraint under its sanitised identifier.
struct Names {
  std::string jointNames, jointQ, jointV, jointIds, consNames, consRow, consRows, consIds, empty;
};
Names namesAndSlots(const Plan& plan) {
  Names n;
  IdentifierSet jointIds;  // joints have no identifier in the plan: made here, unique by position
  const auto sep = [](const std::string& s) { return s.empty() ? "" : ", "; };
  for (std::size_t i = 1; i < plan.bodies.size(); ++i) {
    const BodyPlan& b = plan.bodies[i];
    const int k = int(i) - 1;
    n.jointNames += sep(n.jointNames) + cStringLiteral(b.joint);
    n.jointQ += fmt::format("{}{}", sep(n.jointQ), b.idx_q);
    n.jointV += fmt::format("{}{}", sep(n.jointV), b.idx_v);
    n.jointIds += fmt::format("inline constexpr int {} = {};\n", jointIds.make(b.joint, k), k);
  }
  for (std::size_t k = 0; k < plan.constraints.size(); ++k) {
    const ConstraintPlan& c = plan.constraints[k];
    n.consNames += sep(n.consNames) + cStringLiteral(c.name);
    n.consRow += fmt::format("{}{}", sep(n.consRow), c.row);
    n.consRows += fmt::format("{}{}", sep(n.consRows), c.rows);
    n.consIds += fmt::format("inline constexpr int {} = {};\n", c.ident, k);
  }
  // A C++ array cannot be empty: one placeholder entry, said so.
  if (n.jointNames.empty()) {
    n.jointNames = "nullptr", n.jointQ = n.jointV = "0";
    n.empty += "\n// No joints: the joint arrays hold one placeholder entry (nullptr, 0).";
  }
  if (n.consNames.empty()) {
    n.consNames = "nullptr", n.consRow = n.consRows = "0";
    n.empty += "\n// No constraints (ncons = 0): the constraint arrays hold one placeholder entry (nullptr, 0).";
  }
  return n;
}

// major.minor of PROXGEN_VERSION ("0.1.0").
std::pair<int, int> versionNumbers() {
  int major = 0, minor = 0;
  if (std::sscanf(PROXGEN_VERSION, "%d.%d", &major, &minor) != 2) throw std::logic_error("PROXGEN_VERSION is not major.minor");
  return {major, minor};
}

}  // namespace

SolverFiles assembleFiles(const System& sys, const Plan& plan, const SolverInputs& in, const Members& ws,
                          const SolverTexts& texts) {
  const Model& m = sys.model;
  const int scalarBytes = plan.scalar == ScalarType::Float ? 4 : 8;

  std::string joints;
  for (int i = 1; i < m.numBodies(); ++i) {
    const BodyPlan& b = plan.bodies[std::size_t(i)];
    joints += fmt::format("//   q[{}..{}] v[{}..{}]  joint '{}' ({}), link '{}'\n", b.idx_q, b.idx_q + b.nq - 1, b.idx_v,
                          b.idx_v + b.nv - 1, escapeComment(b.joint), jointClassName(b.jointClass), escapeComment(b.link));
  }
  std::string constraints;
  for (const ConstraintPlan& c : plan.constraints)
    constraints += fmt::format("//   lambda[{}..{}]  '{}' ({}) on link '{}'\n", c.row, c.row + c.rows - 1, escapeComment(c.name),
                               c.weld ? "6d weld" : "3d point contact", escapeComment(c.link));
  if (constraints.empty()) constraints = "//   (none)\n";

  const std::string banner = fmt::format(
      fmt::runtime(kBannerTemplate), fmt::arg("version", PROXGEN_VERSION), fmt::arg("urdf", escapeComment(in.urdfName)),
      fmt::arg("layout", escapeComment(in.layoutName)), fmt::arg("command", escapeComment(in.command)),
      fmt::arg("robot", escapeComment(m.name)), fmt::arg("urdf_sha", in.urdfSha256), fmt::arg("layout_sha", in.layoutSha256),
      fmt::arg("operations", opLine("constrained_aba", texts.cabaOps, plan.iterations) +
                                 opLine("prox_pv", texts.pvOps, plan.iterations)));

  SolverFiles files;
  files.headerName = plan.name + ".hpp";
  files.sourceName = plan.name + ".cpp";
  const CodeBuilder lit(plan.scalar);
  const Names n = namesAndSlots(plan);
  const auto [major, minor] = versionNumbers();
  files.header = fmt::format(
      fmt::runtime(kHeaderTemplate), fmt::arg("banner", banner),
      fmt::arg("q_convention", plan.floatingBase ? "x y z qx qy qz qw of the base, then one value per joint"
                                                 : "one value per joint"),
      fmt::arg("joint_table", joints), fmt::arg("constraint_table", constraints), fmt::arg("name", plan.name),
      fmt::arg("scalar", scalarName(plan.scalar)), fmt::arg("nq", plan.nq), fmt::arg("nv", plan.nv),
      fmt::arg("nc", plan.nc), fmt::arg("mu", lit.literal(plan.mu)), fmt::arg("iterations", plan.iterations),
      fmt::arg("workspace_bytes", ws.scalars() * scalarBytes), fmt::arg("members", ws.declarations()),
      fmt::arg("ncons", plan.constraints.size()), fmt::arg("version", PROXGEN_VERSION), fmt::arg("version_major", major),
      fmt::arg("version_minor", minor), fmt::arg("empty_arrays", n.empty), fmt::arg("joint_names", n.jointNames),
      fmt::arg("joint_idx_q", n.jointQ), fmt::arg("joint_idx_v", n.jointV), fmt::arg("joint_ids", n.jointIds),
      fmt::arg("constraint_names", n.consNames), fmt::arg("constraint_row", n.consRow),
      fmt::arg("constraint_rows", n.consRows), fmt::arg("constraint_ids", n.consIds));
  files.source = fmt::format(fmt::runtime(kSourceTemplate), fmt::arg("banner", banner), fmt::arg("name", plan.name),
                             fmt::arg("parts", texts.parts), fmt::arg("kinematics", texts.kinematics),
                             fmt::arg("free_bodies", freeBodies(texts)),
                             fmt::arg("caba", texts.caba), fmt::arg("pv", texts.pv),
                             fmt::arg("residual", plan.nc > 0 ? "  return proxgen_rt::largest_magnitude_of<nc>(w.residual);\n"
                                                              : "  static_cast<void>(w);\n  return Scalar(0);\n"));
  return files;
}

}  // namespace proxgen::emit
