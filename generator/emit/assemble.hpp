// The file assembly of a generated solver: the banner, the header (joint and
// constraint tables, Settings, the Workspace from the member registry) and the
// source (the part functions, then the hosts and the entry points), filled
// into templates/*.tpl.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "emit/emitter.hpp"
#include "emit/expr.hpp"
#include "emit/members.hpp"
#include "emit/shared_blocks.hpp"

namespace proxgen::emit {

/// The printed bodies of the functions of templates/solver.cpp.tpl.
struct SolverTexts {
  std::string parts;  // every part function, after shareBlocks
  std::string unsharedParts;  // the same before it (the lane code's: batch.cpp)
  std::vector<SharedKernel> sharedKernels;
  std::string kinematics, eliminateFree, accelerateFree, caba, pv;
  OpCount cabaOps, pvOps;  // per call of each entry point, everything it calls included
  // What the solver holds (System::functions); the library's entry points
  // (inverse_dynamics, ...: not the two solvers) with their operations per
  // call, and the helper they share ("" when none needs it).
  FunctionSet functions;
  std::map<Function, std::string> library;
  std::map<Function, OpCount> libraryOps;
  std::string jointTransforms;
  // inverse_dynamics_derivatives' sweep after the kinematics pass ("" when not held);
  // its helpers world_frame_rows and world_frame_columns are printed with it.
  std::string tangentSweep;
  // mass_matrix_inverse's passes after the joint transforms ("" when not held),
  // the same after prox_pv's elimination of the same q (constrained_dynamics_derivatives),
  // and the forward pass both end with.
  std::string minvPasses, minvFactored, minvForward;
  bool withKinematics = false, withJointTransforms = false;
  // The helper of the constraint functions of q alone ("" when none is held).
  std::string constraintJoints;
};

/// Every function the source defines besides the part functions (the entry
/// points, the helpers above and the dense templates): a part function is named
/// after its host and its first body, and may take none of these names (a link
/// called "bodies" would otherwise make a part eliminate_free_bodies).
const std::vector<std::string>& fileFunctionNames();

SolverFiles assembleFiles(const System& sys, const Plan& plan, const SolverInputs& in, const Members& ws,
                          const SolverTexts& texts);

}  // namespace proxgen::emit
