// The functions of a generated solver, in the order they are printed: each is
// a host written by FunctionWriter (function.hpp) from the passes
// (passes.hpp, one file each); assemble.cpp puts them into the two files.
#include "emit/emitter.hpp"

#include "emit/assemble.hpp"
#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

// The constraint functions that are selected (pass_constraint_kinematics.cpp,
// pass_delassus.cpp); kin's values (after kinematics) live in `from`.
void emitConstraintFunctions(Emit& e, const Kinematics& kin, const CodeBuilder* from, SolverTexts& texts) {
  const FunctionSet& f = e.sys.functions;
  const bool delassus = f.has(Function::Delassus) || f.has(Function::DelassusInverse);
  ConstraintJoints joints;
  if (delassus || f.has(Function::ConstraintPlacements) || f.has(Function::ConstraintJacobian)) {
    joints = emitConstraintJoints(e, delassus);
    texts.constraintJoints = joints.text;
  }
  if (f.has(Function::ConstraintPlacements)) texts.placements = emitConstraintPlacements(e, joints);
  if (f.has(Function::ConstraintJacobian)) texts.jacobian = emitConstraintJacobian(e, joints);
  if (f.has(Function::ConstraintDrift)) texts.drift = emitConstraintDrift(e, kin, from);
  if (f.has(Function::Delassus)) texts.delassus = emitDelassus(e, joints, false);
  if (f.has(Function::DelassusInverse)) texts.delassusInverse = emitDelassus(e, joints, true);
}

}  // namespace

SolverFiles emitSolver(const System& sys, const Plan& plan, const SolverInputs& inputs, SolverStats* stats) {
  Members ws;
  std::vector<std::string> bodyNames;
  for (const BodyPlan& b : plan.bodies) bodyNames.push_back(b.ident);
  FunctionWriter fn(plan.scalar, bodyNames);
  FreeAccelerations freeAccel;
  Emit e{sys, plan, ws, fn, &freeAccel};
  SolverTexts texts;

  // kinematics(q, v, w): shared by both entry points.
  fn.beginHost("kinematics", nullptr);
  Kinematics kin = emitKinematics(e);
  fn.live().kin = &kin;
  texts.kinematics = fn.endHost({"q", "v", "w"});

  // eliminate_free_bodies(tau, w): the off-support bodies, shared too (none
  // when every body is on the support).
  Articulated free = startElimination(kin);
  const CodeBuilder* afterElimination = fn.lastHost();
  if (!plan.offSupport.empty()) {
    fn.beginHost("eliminate_free", fn.lastHost());
    free = eliminateFreeBodies(e, kin);
    fn.live().art = &free;
    texts.eliminateFree = fn.endHost({"tau", "w"});
    afterElimination = fn.lastHost();
  }
  fn.live() = Live{};

  // The entry points, each from its own copy of that state; the first one
  // also prints accelerate_free_bodies.
  texts.caba = emitConstrainedAba(e, kin, free, afterElimination);
  texts.pv = emitProxPv(e, kin, free, afterElimination);
  texts.accelerateFree = freeAccel.text;
  emitConstraintFunctions(e, kin, afterElimination, texts);
  texts.parts = fn.parts();

  // Operations per call: each entry point calls kinematics and the two
  // functions of the off-support bodies once (raw lines, not parts).
  OpCount shared = fn.hostOps("kinematics");
  shared += fn.hostOps("eliminate_free");
  shared += fn.hostOps("accelerate_free");
  texts.cabaOps = fn.hostOps("caba");
  texts.cabaOps += shared;
  texts.pvOps = fn.hostOps("pv");
  texts.pvOps += shared;

  if (stats) {
    stats->statements = fn.stats().statements;
    stats->temporaries = fn.stats().temporaries;
    stats->multiplies = fn.stats().multiplies;
    stats->workspaceScalars = ws.scalars();
  }
  return assembleFiles(sys, plan, inputs, ws, texts);
}

}  // namespace proxgen::emit
