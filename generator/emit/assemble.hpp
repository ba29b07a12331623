// The file assembly of a generated solver: the banner, the header (joint and
// constraint tables, Settings, the Workspace from the member registry) and the
// source (the part functions, then the hosts and the entry points), filled
// into templates/*.tpl.
#pragma once

#include <string>

#include "emit/emitter.hpp"
#include "emit/expr.hpp"
#include "emit/members.hpp"

namespace proxgen::emit {

/// The printed bodies of the functions of templates/solver.cpp.tpl.
struct SolverTexts {
  std::string parts;  // every part function
  std::string kinematics, eliminateFree, accelerateFree, caba, pv;
  OpCount cabaOps, pvOps;  // per call of each entry point, everything it calls included
  // The constraint functions' bodies (empty: not selected) and their helper constraint_joints.
  std::string constraintJoints, placements, jacobian, drift, delassus, delassusInverse;
};

SolverFiles assembleFiles(const System& sys, const Plan& plan, const SolverInputs& in, const Members& ws,
                          const SolverTexts& texts);

}  // namespace proxgen::emit
