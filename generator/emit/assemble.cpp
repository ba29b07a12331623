#include "emit/assemble.hpp"

#include <fmt/format.h>

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
  files.header = fmt::format(
      fmt::runtime(kHeaderTemplate), fmt::arg("banner", banner),
      fmt::arg("q_convention", plan.qConvention),
      fmt::arg("joint_table", joints), fmt::arg("constraint_table", constraints), fmt::arg("name", plan.name),
      fmt::arg("scalar", scalarName(plan.scalar)), fmt::arg("nq", plan.nq), fmt::arg("nv", plan.nv),
      fmt::arg("nc", plan.nc), fmt::arg("mu", lit.literal(plan.mu)), fmt::arg("iterations", plan.iterations),
      fmt::arg("workspace_bytes", ws.scalars() * scalarBytes), fmt::arg("members", ws.declarations()));
  files.source = fmt::format(fmt::runtime(kSourceTemplate), fmt::arg("banner", banner), fmt::arg("name", plan.name),
                             fmt::arg("parts", texts.parts), fmt::arg("kinematics", texts.kinematics),
                             fmt::arg("free_bodies", freeBodies(texts)),
                             fmt::arg("caba", texts.caba), fmt::arg("pv", texts.pv));
  return files;
}

}  // namespace proxgen::emit
