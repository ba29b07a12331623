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

// The constraint functions that were selected (docs/dynamics.md): their
// declarations for the header, their definitions, and constraint_joints (the
// joint transforms they share) for the source's anonymous namespace.
struct ConstraintFunctionTexts {
  std::string declarations, definitions, helper;
};
ConstraintFunctionTexts constraintFunctions(const SolverTexts& t) {
  struct One {
    const std::string& body;
    const char *doc, *signature;
  };
  const One all[] = {
      {t.placements,
       "// Per constraint (layout order) 12 values: its frame's rotation in the world\n"
       "// (3 x 3, row-major), then the frame's origin in the world.\n",
       "void constraint_placements(const Scalar* q, Workspace& w, Scalar* X) noexcept"},
      {t.jacobian, "// J (nc x nv, row-major): the constraint frames' velocity rows are J v.\n",
       "void constraint_jacobian(const Scalar* q, Workspace& w, Scalar* J) noexcept"},
      {t.drift,
       "// gamma (nc): J qdd + gamma is the constraint frames' acceleration the solvers\n"
       "// hold to a* (of a point, the classical acceleration of its origin).\n",
       "void constraint_drift(const Scalar* q, const Scalar* v, Workspace& w, Scalar* gamma) noexcept"},
      {t.delassus,
       "// G = J M^-1 J^T (nc x nc, row-major), by a recursion over the constraint\n"
       "// support: neither M nor J is formed.\n",
       "void delassus(const Scalar* q, Workspace& w, Scalar* G) noexcept"},
      {t.delassusInverse,
       "// (G + I / s.mu)^-1 (nc x nc, row-major) = mu I - mu^2 J (M + mu J^T J)^-1 J^T by the\n"
       "// same recursion with the penalty mu J^T J, no nc x nc factorisation. The two\n"
       "// terms cancel: its absolute round-off is about eps kappa(M + mu J^T J) mu (in\n"
       "// float at large mu, factor delassus's G instead).\n",
       "void delassus_inverse(const Scalar* q, const Settings& s, Workspace& w, Scalar* Ginv) noexcept"},
  };
  ConstraintFunctionTexts out;
  for (const One& f : all) {
    if (f.body.empty()) continue;
    out.declarations += fmt::format("{}{};\n", f.doc, f.signature);
    out.definitions += fmt::format("\n{}{} {{\n{}}}\n", f.doc, f.signature, f.body);
  }
  if (!out.declarations.empty())
    out.declarations = "\n// The constraint functions: rows in layout order, in the constraint frames the\n"
                       "// solvers use (6d weld: [linear; angular] of the frame, in the frame; 3d point:\n"
                       "// the linear rows); the constraint force on the robot is -J^T lambda.\n" +
                       out.declarations;
  if (!t.constraintJoints.empty())
    out.helper = fmt::format("// Joint transforms, for the constraint functions of q alone.\n"
                             "void constraint_joints(const Scalar* q, Workspace& w) noexcept {{\n{}}}\n\n",
                             t.constraintJoints);
  return out;
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
  const ConstraintFunctionTexts cons = constraintFunctions(texts);
  files.header = fmt::format(
      fmt::runtime(kHeaderTemplate), fmt::arg("banner", banner),
      fmt::arg("q_convention", plan.floatingBase ? "x y z qx qy qz qw of the base, then one value per joint"
                                                 : "one value per joint"),
      fmt::arg("joint_table", joints), fmt::arg("constraint_table", constraints), fmt::arg("name", plan.name),
      fmt::arg("scalar", scalarName(plan.scalar)), fmt::arg("nq", plan.nq), fmt::arg("nv", plan.nv),
      fmt::arg("nc", plan.nc), fmt::arg("mu", lit.literal(plan.mu)), fmt::arg("iterations", plan.iterations),
      fmt::arg("workspace_bytes", ws.scalars() * scalarBytes), fmt::arg("members", ws.declarations()),
      fmt::arg("constraint_declarations", cons.declarations));
  files.source = fmt::format(fmt::runtime(kSourceTemplate), fmt::arg("banner", banner), fmt::arg("name", plan.name),
                             fmt::arg("parts", texts.parts), fmt::arg("kinematics", texts.kinematics),
                             fmt::arg("free_bodies", freeBodies(texts)),
                             fmt::arg("caba", texts.caba), fmt::arg("pv", texts.pv),
                             fmt::arg("constraint_joints", cons.helper), fmt::arg("constraint_functions", cons.definitions));
  return files;
}

}  // namespace proxgen::emit
