// What generation decides, as plain data (docs/design.md, "Plan"): per body its
// joint class, its identifier, whether it is on the constraint support, the
// constraint rows of its subtree and where they sit in its parent's; the
// support and off-support bodies; the Delassus rows in tree order. The emitter
// prints from this and the System. The tree facts (support, subtree rows,
// tree-order positions) are the model's ConstraintTree, computed once
// (model/tree.cpp) and read by the generic solvers' Data too.
#pragma once

#include <string>
#include <vector>

#include "emit/expr.hpp"
#include "model/model.hpp"

namespace proxgen::emit {

enum class JointClass {
  RevoluteX, RevoluteY, RevoluteZ, RevoluteAxis,      // about +-x/y/z, or a general unit axis
  PrismaticX, PrismaticY, PrismaticZ, PrismaticAxis,  // along +-x/y/z, or a general unit axis
  FreeFlyer,
  Planar,  // x, y, yaw in the joint frame's x-y plane: S picks linear x, linear y, angular z
};
const char* jointClassName(JointClass c);
/// The components of a spatial vector ([linear; angular]) a free flyer's or a
/// planar joint's S columns pick, one per dof (S = [e_k ...], constant in the
/// body frame): 0..5, and 0, 1, 5. Empty for a one-dof joint.
std::vector<int> pickedComponents(JointClass c);

struct BodyPlan {
  int index = 0;
  int parent = -1;
  std::string link, joint;   // raw names (comments only, escaped)
  std::string ident;         // sanitised, unique: v_<ident>, IA_<ident>, ...
  JointClass jointClass = JointClass::RevoluteZ;
  int axis = -1;             // 0/1/2 for an axis along x/y/z, else -1
  double axisSign = 1.0;     // +1 or -1 for such an axis
  int idx_q = 0, nq = 0, idx_v = 0, nv = 0;
  /// One past the last dof of the subtree: its dofs are [idx_v, dofEnd)
  /// (depth-first order makes them contiguous; the world's: all nv).
  int dofEnd = 0;
  std::vector<int> children;
  bool onSupport = false;
  std::vector<int> constraints;  // constraints on this body (indices, layout order)
  /// Constraint rows (layout numbering) of the subtree, in subtree order: the
  /// body's own rows, then each child's subtree in child order.
  std::vector<int> subtreeRows;
  /// First column of this subtree's rows in the parent's KA / LA / lA.
  int offsetInParent = 0;
  /// Position of the subtree's first row in the root's (tree) order: its rows
  /// are the block [rowStart, rowStart + m()) of rootRows.
  int rowStart = 0;
  /// Zero patterns known at generation time (for the docs and the tests).
  int treeRotationNonzeros = 0;     // of 9
  int treeTranslationNonzeros = 0;  // of 3
  int inertiaNonzeros = 0;          // of the 21 entries of the symmetric 6x6
  bool needsGravity = false;        // on the support: carries R_i^T g for the k_i terms
  bool needsPlacement = false;      // on a path to a constraint with kp != 0: world placement
  /// The same for bodies whose subtrees are alike (joint classes and axes,
  /// support, constraint kinds; not the constants): a left and a right leg's
  /// links, a hand's fingers. Twins one after the other in the sweep share a
  /// part function, so that their blocks can run as a pair.
  std::string shape;
  int m() const { return int(subtreeRows.size()); }
};

struct ConstraintPlan {
  std::string name, link;  // raw (comments only)
  std::string ident;
  int body = 0;
  int row = 0, rows = 0;
  bool weld = true;  // 6d, else 3d point contact
};

struct Plan {
  std::string name;  // namespace, sanitised
  ScalarType scalar = ScalarType::Double;
  int nq = 0, nv = 0, nc = 0;
  bool floatingBase = false;
  std::string qConvention;  // the header's "q = [...]" line
  double mu = 1e4;
  int iterations = 3;
  std::vector<BodyPlan> bodies;      // [0] = the world
  /// The moving bodies in the order the forward sweeps visit them (the
  /// backward sweeps: reversed): breadth first, so the same link of limbs
  /// that repeat (Talos' legs, a hand's fingers) comes one after the other and
  /// their blocks can run side by side (docs/emitter.md, "Blocks in pairs").
  std::vector<int> sweep;
  std::vector<int> support;          // in sweep order: parents before children
  std::vector<int> offSupport;       // the other moving bodies, in sweep order
  std::vector<int> rootRows;         // Delassus rows in tree order (= bodies[0].subtreeRows)
  std::vector<int> rowPosition;      // per layout row: its position in rootRows
  std::vector<ConstraintPlan> constraints;  // layout order
};

/// The plan of one solver; `name` is sanitised into the namespace name.
Plan makePlan(const System& sys, const std::string& name, ScalarType scalar);

}  // namespace proxgen::emit
