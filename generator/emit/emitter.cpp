// The functions of a generated solver, in the order they are printed: each is
// a host written by FunctionWriter (function.hpp) from the passes
// (passes.hpp, one file each); assemble.cpp puts them into the two files.
// System::functions says which are printed; a helper (kinematics,
// joint_transforms, the off-support bodies' functions) only when one needs it.
#include "emit/emitter.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "emit/assemble.hpp"
#include "emit/passes.hpp"
#include "emit/shared_blocks.hpp"

namespace proxgen::emit {
namespace {

// The constraint functions that are selected (pass_constraint_kinematics.cpp,
// pass_delassus.cpp); kin's values (after kinematics) live in `from`.
void emitConstraintFunctions(Emit& e, const Kinematics& kin, const CodeBuilder* from, SolverTexts& texts) {
  const FunctionSet& f = e.sys.functions;
  const bool delassus = f.has(Function::Delassus) || f.has(Function::DelassusInverse);
  ConstraintJoints joints;
  if (delassus || f.has(Function::ConstraintPlacements) || f.has(Function::ConstraintJacobian) ||
      f.has(Function::ConstraintWrenches)) {
    joints = emitConstraintJoints(e, delassus);
    texts.constraintJoints = joints.text;
  }
  if (f.has(Function::ConstraintPlacements))
    texts.library[Function::ConstraintPlacements] = emitConstraintPlacements(e, joints);
  if (f.has(Function::ConstraintJacobian)) texts.library[Function::ConstraintJacobian] = emitConstraintJacobian(e, joints);
  if (f.has(Function::ConstraintDrift)) texts.library[Function::ConstraintDrift] = emitConstraintDrift(e, kin, from);
  if (f.has(Function::Delassus)) texts.library[Function::Delassus] = emitDelassus(e, joints, false);
  if (f.has(Function::DelassusInverse)) texts.library[Function::DelassusInverse] = emitDelassus(e, joints, true);
  if (f.has(Function::ConstraintWrenches)) texts.library[Function::ConstraintWrenches] = emitConstraintWrenches(e, joints);
}

}  // namespace

SolverFiles emitSolver(const System& sys, const Plan& plan, const SolverInputs& inputs, SolverStats* stats) {
  Members ws;
  std::vector<std::string> bodyNames, bodyShapes;
  for (const BodyPlan& b : plan.bodies) bodyNames.push_back(b.ident), bodyShapes.push_back(b.shape);
  FunctionWriter fn(plan.scalar, bodyNames, bodyShapes);
  for (const std::string& name : fileFunctionNames()) fn.reserveName(name);
  FreeAccelerations freeAccel;
  Emit e{sys, plan, ws, fn, &freeAccel};
  SolverTexts texts;
  // A derivative function calls the functions it is made of: the file holds
  // them as well (`calls`). Its operations per call are its host's, the whole
  // of calls.front() (the function that leaves the kinematics state of its
  // (q, v) in the workspace) and the hosts it calls after it without their
  // transforms and kinematics: mass_matrix_inverse's passes ("minv" and its
  // forward pass "minv_forward"; for cdd "minvf", the backward pass on
  // prox_pv's factors) and the tangent sweep of inverse_dynamics_derivatives ("rnead").
  struct Composite {
    Function f;
    const char* host;
    std::vector<Function> calls;
    std::vector<const char*> hosts;
  };
  const Composite composites[] = {
      {Function::ForwardDynamicsDerivatives, "fdd",
       {Function::NonlinearEffects, Function::MassMatrixInverse, Function::InverseDynamicsDerivatives},
       {"minv", "minv_forward", "rnead"}},
      {Function::ConstrainedDynamicsDerivatives, "cdd",
       {Function::ProxPv, Function::MassMatrixInverse, Function::InverseDynamicsDerivatives},
       {"minvf", "minv_forward", "rnead"}}};
  FunctionSet want = sys.functions;
  for (const Composite& c : composites)
    if (want.has(c.f))
      for (Function f : c.calls) want.add(f);
  texts.functions = want;
  const bool solvers = want.has(Function::ConstrainedAba) || want.has(Function::ProxPv);
  // (inverse_dynamics has its own forward sweep: pass_inverse_dynamics.cpp.)
  texts.withKinematics = solvers || want.has(Function::NonlinearEffects) || want.has(Function::ConstraintDrift) ||
                         want.has(Function::InverseDynamicsDerivatives);
  texts.withJointTransforms = want.has(Function::MassMatrix) || want.has(Function::MassMatrixInverse);

  // kinematics(q, v, w): shared by the entry points with a velocity.
  Kinematics kin;
  const CodeBuilder* afterKinematics = nullptr;
  if (texts.withKinematics) {
    fn.beginHost("kinematics", nullptr);
    kin = emitKinematics(e);
    fn.live().kin = &kin;
    texts.kinematics = fn.endHost({"q", "v", "w"});
    afterKinematics = fn.lastHost();
  }
  // The state as kinematics left it, in its host's values (the solvers' hosts
  // below move `kin` on into eliminate_free_bodies).
  const Kinematics afterKinematicsState = kin;
  ProxPvEnd pvEnd;  // what prox_pv leaves in the workspace (read by cdd's M^-1)

  if (solvers) {
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
    if (want.has(Function::ConstrainedAba)) texts.caba = emitConstrainedAba(e, kin, free, afterElimination);
    if (want.has(Function::ProxPv)) texts.pv = emitProxPv(e, kin, free, afterElimination, &pvEnd);
    texts.accelerateFree = freeAccel.text;
  }

  // The dynamics library (docs/dynamics.md), after the solvers: their members
  // come first in the Workspace, so a solver without these is what it was.
  if (want.has(Function::InverseDynamics))
    texts.library[Function::InverseDynamics] = emitInverseDynamics(e, afterKinematicsState, afterKinematics, false);
  if (want.has(Function::NonlinearEffects))
    texts.library[Function::NonlinearEffects] = emitInverseDynamics(e, afterKinematicsState, afterKinematics, true);
  // Both derivative functions that call the sweep read dtau's pattern, and
  // constrained_dynamics_derivatives' rows the world-frame vectors it left.
  const bool cdd = want.has(Function::ConstrainedDynamicsDerivatives);
  BodyTangents tangents;
  if (want.has(Function::InverseDynamicsDerivatives)) {
    texts.tangentSweep = emitInverseDynamicsDerivatives(e, afterKinematicsState, afterKinematics, &tangents);
    // The sweep writes dtau's pattern; the caller's outputs get zeros elsewhere.
    const int nv2 = plan.nv * plan.nv;
    texts.library[Function::InverseDynamicsDerivatives] =
        fmt::format("  kinematics(q, v, w);\n  for (int k = 0; k < {0}; ++k) dtau_dq[k] = Scalar(0);\n"
                    "  for (int k = 0; k < {0}; ++k) dtau_dv[k] = Scalar(0);\n"
                    "  tangent_sweep(q, v, qdd, lambda, w, dtau_dq, dtau_dv);\n",
                    nv2);
  }
  if (texts.withJointTransforms) {
    fn.beginHost("joint_transforms", nullptr);
    Kinematics transforms = emitJointTransforms(e);
    fn.live().kin = &transforms;
    texts.jointTransforms = fn.endHost({"q", "w"});
    fn.live() = Live{};
    const CodeBuilder* afterTransforms = fn.lastHost();
    if (want.has(Function::MassMatrix))
      texts.library[Function::MassMatrix] = emitMassMatrix(e, transforms, afterTransforms);
    if (want.has(Function::MassMatrixInverse)) {
      texts.minvPasses = emitMassMatrixInverse(e, transforms, afterTransforms, nullptr, &texts.minvForward);
      texts.library[Function::MassMatrixInverse] =
          "  joint_transforms(q, w);\n  mass_matrix_inverse_passes(q, w, Minv);\n";
    }
  }

  if (want.has(Function::ForwardDynamicsDerivatives))
    texts.library[Function::ForwardDynamicsDerivatives] = emitForwardDynamicsDerivatives(e, tangents);
  if (cdd) {
    // M^-1 after prox_pv of the same q: its elimination's U and D^-1 (docs/derivatives.md section 5).
    texts.minvFactored = emitMassMatrixInverse(e, pvEnd.kin, pvEnd.host, &pvEnd.art);
    texts.library[Function::ConstrainedDynamicsDerivatives] =
        emitConstrainedDynamicsDerivatives(e, tangents);
  }

  // The constraint functions (pass_constraint_kinematics.cpp, pass_delassus.cpp).
  emitConstraintFunctions(e, afterKinematicsState, afterKinematics, texts);
  texts.parts = fn.parts();

  // Operations per call, and the hosts each entry point runs (for the shared
  // blocks below): each entry point calls kinematics and the two functions of
  // the off-support bodies once (raw lines, not parts).
  std::map<Function, std::vector<std::string>> reach;
  auto sum = [&](const std::vector<std::string>& hosts) {
    OpCount ops;
    for (const std::string& h : hosts) ops += fn.hostOps(h);
    return ops;
  };
  reach[Function::ConstrainedAba] = {"caba", "kinematics", "eliminate_free", "accelerate_free"};
  reach[Function::ProxPv] = {"pv", "kinematics", "eliminate_free", "accelerate_free"};
  texts.cabaOps = sum(reach[Function::ConstrainedAba]);
  texts.pvOps = sum(reach[Function::ProxPv]);
  const struct {
    Function f;
    const char* host;
    const char* helper;  // the helper it calls, or none
  } library[] = {{Function::InverseDynamics, "rnea", nullptr},  // its own forward sweep
                 {Function::NonlinearEffects, "nle", "kinematics"},
                 {Function::MassMatrix, "crba", "joint_transforms"},
                 {Function::MassMatrixInverse, "minv", "joint_transforms"},
                 {Function::ConstraintPlacements, "placements", "joints"},
                 {Function::ConstraintJacobian, "jacobian", "joints"},
                 {Function::ConstraintDrift, "drift", "kinematics"},
                 {Function::Delassus, "delassus", "joints"},
                 {Function::DelassusInverse, "dinv", "joints"},
                 {Function::ConstraintWrenches, "wrenches", "joints"},
                 {Function::InverseDynamicsDerivatives, "rnead", "kinematics"}};
  for (const auto& l : library) {
    reach[l.f] = {l.host};
    if (l.helper) reach[l.f].push_back(l.helper);
    if (l.f == Function::MassMatrixInverse) reach[l.f].push_back("minv_forward");  // its second helper
    texts.libraryOps[l.f] = sum(reach[l.f]);
  }
  // The derivatives: their host (the dense products included) and the functions it calls.
  for (const Composite& c : composites) {
    if (!want.has(c.f)) continue;
    std::vector<std::string> hosts = reach[c.calls.front()];
    hosts.push_back(c.host);
    for (const char* h : c.hosts) hosts.push_back(h);
    reach[c.f] = hosts;
    texts.libraryOps[c.f] = sum(hosts);
  }

  // Shared blocks (shared_blocks.hpp): the parts of a host whose every entry
  // point in the file has code of kSharedBlocksMinOps operations or more.
  std::map<std::string, long> smallest;  // host -> the smallest code of an entry point that runs it
  for (const auto& [f, hosts] : reach) {
    if (!want.has(f)) continue;
    const OpCount ops = sum(hosts);
    const long size = ops.once.total() + ops.perK.total();
    for (const std::string& h : hosts) {
      auto [it, inserted] = smallest.emplace(h, size);
      if (!inserted) it->second = std::min(it->second, size);
    }
  }
  texts.unsharedParts = texts.parts;
  SharedParts shared = shareBlocks(texts.parts, ws, [&](const std::string& part) {
    const auto it = smallest.find(fn.hostOf(part));
    return it != smallest.end() && it->second >= kSharedBlocksMinOps;
  }, true);
  texts.parts = std::move(shared.parts);
  texts.sharedKernels = std::move(shared.kernels);

  if (stats) {
    stats->statements = fn.stats().statements;
    stats->temporaries = fn.stats().temporaries;
    stats->multiplies = fn.stats().multiplies;
    stats->workspaceScalars = ws.scalars();
  }
  return assembleFiles(sys, plan, inputs, ws, texts);
}

}  // namespace proxgen::emit
