// The robot model shared by the generic solvers and the code generator.
//
// A Model is a kinematic tree of bodies in depth-first order. Body 0 is the
// world. Every other body i has one moving joint connecting it to its parent
// p(i) < i: revolute (URDF revolute and continuous), prismatic, planar (URDF
// planar, or the root with `base: planar`) or a free flyer (URDF floating on a
// link fixed to the world, or the root with `base: floating`). URDF links on
// fixed joints are merged into the moving body they hang from; they remain
// available as frames (constraint sites). Joint conventions: docs/design.md,
// "Conventions".
#pragma once

#include <string>
#include <vector>

#include "model/functions.hpp"
#include "model/spatial.hpp"

namespace proxgen {

// Planar: q = [x y cos(yaw) sin(yaw)], v = [vx vy wz] in the body frame, the
// plane the joint frame's x-y plane (Pinocchio's JointModelPlanar).
enum class JointType { Revolute, Prismatic, FreeFlyer, Planar };

/// How the URDF's root link is attached to the world (layout `base`).
enum class BaseType { Fixed, Floating, Planar };

const char* jointTypeName(JointType t);

struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  std::string urdfType;  // "revolute", "continuous", "prismatic", "planar" or "floating" (free flyer)
  Vec3 axis = Vec3::UnitZ();  // unit axis in the body frame (revolute/prismatic)
  int idx_q = 0, nq = 1;      // slots in q
  int idx_v = 0, nv = 1;      // slots in v, qdd, tau
  bool hasPositionLimits = false;
  double lower = 0, upper = 0, velocityLimit = 0, effortLimit = 0;
  std::string mimicOf;  // non-empty when the URDF declared <mimic>; solved as independent
};

struct Body {
  std::string link;   // URDF link whose frame is the body frame
  int parent = -1;    // parent body index (-1 for the world)
  SE3 treePlacement;  // X_T: joint frame in the parent body frame at q = 0
  Joint joint;        // the joint between parent and this body
  Inertia inertia;    // this link plus every link merged into it by fixed joints
  std::vector<int> children;
};

/// A URDF link, as a frame rigidly attached to a body.
struct Frame {
  std::string name;  // the URDF link name
  int body = 0;      // body it is attached to
  SE3 placement;     // frame in body coordinates
  std::string viaJoint;  // the URDF joint whose child this link is ("" for the root link)
};

struct Model {
  std::string name;        // <robot name>
  std::string sourcePath;  // file it was read from
  std::vector<Body> bodies;  // [0] = world, then depth-first
  std::vector<Frame> frames;  // every URDF link, in body order
  int nq = 0, nv = 0;
  Vec3 gravity{0, 0, -9.81};
  bool floatingBase = false;  // body 1 is a free flyer on the world (`base: floating` or a URDF floating joint)
  bool planarBase = false;    // body 1 is a planar joint on the world (`base: planar` or a URDF planar joint)
  std::vector<std::string> warnings;  // e.g. mimic joints solved as independent joints

  int numBodies() const { return int(bodies.size()); }  // including the world
  /// Index of the frame for a URDF link name, or -1.
  int findFrame(const std::string& link) const;
  /// Index of the body whose joint is called `joint`, or -1.
  int findJointBody(const std::string& joint) const;
  /// Motion subspace S_i (6 x nv_i) in body coordinates.
  Mat6X motionSubspace(int i) const;
  /// Placement of body i in its parent at configuration q: X_T,i * X_J(q_i).
  SE3 jointPlacement(int i, const Eigen::Ref<const VecX>& q) const;
  /// q at the neutral configuration (zeros; identity quaternion for a free
  /// flyer, (cos, sin) = (1, 0) for a planar joint).
  VecX neutral() const;
  /// Bodies on the path from body i to the root, i first, world excluded.
  std::vector<int> pathToRoot(int i) const;
};

enum class ConstraintType { Weld6D, Point3D };

/// One constraint of the layout, bound to the model.
struct Constraint {
  std::string name;
  std::string link;
  ConstraintType type = ConstraintType::Weld6D;
  SE3 offset;         // constraint frame C in the link frame (layout `offset`)
  double kp = 0, kd = 0;  // Baumgarte gains
  bool hasTarget = false;
  SE3 target;         // world placement the frame is held to (needed when kp != 0)
  int linkLine = 0;   // line of `link:` in the layout, for messages (0: unknown)
  // Resolved against the model:
  int body = 0;       // body carrying the link
  SE3 placement;      // C in body coordinates (link frame * offset)
  int row = 0;        // first row in the stacked constraint vector (layout order)
  int rows() const { return type == ConstraintType::Weld6D ? 6 : 3; }
};

/// The constraint layout file (YAML) as read.
struct Layout {
  std::string sourcePath;
  bool floatingBase = false;  // `base: floating`
  bool planarBase = false;    // `base: planar` (never both)
  BaseType base() const { return floatingBase ? BaseType::Floating : planarBase ? BaseType::Planar : BaseType::Fixed; }
  bool hasGravity = false;
  Vec3 gravity{0, 0, -9.81};
  double mu = 1e4;
  int iterations = 3;
  FunctionSet functions;  // `functions: [...]`; default the two solvers
  std::vector<Constraint> constraints;  // unresolved: body/placement/row unset
};

/// A model and its constraints: what every solver, generic or generated, works on.
struct System {
  Model model;
  std::vector<Constraint> constraints;  // resolved, layout order
  int nc = 0;                           // total constraint rows
  double mu = 1e4;                      // defaults from the layout
  int iterations = 3;
  FunctionSet functions;  // what a generated solver of this System holds (model/functions.hpp)
  std::string layoutPath;

  int findConstraint(const std::string& name) const;
  /// Bodies on the support: on a path from a constrained body to the root (ascending order).
  std::vector<int> supportBodies() const;
};

/// The constraint tree of a System, computed once (model/tree.cpp) for the
/// generic solvers (algorithms/data.cpp) and the generated ones (emit/plan.cpp).
struct ConstraintTree {
  std::vector<int> support;                   // = System::supportBodies()
  std::vector<char> onSupport;                // per body
  std::vector<std::vector<int>> subtreeRows;  // per body: its own rows (layout order), then each child's subtree's
  std::vector<int> subtreeStart;              // per body: position of its first row in subtreeRows[0] (tree order)
  std::vector<int> offsetInParent;            // per body: position of its first row in its parent's subtreeRows
  std::vector<int> treePosition;              // per layout row: its position in subtreeRows[0]
};
ConstraintTree constraintTree(const System& sys);

/// Binds a layout's constraints to a model: resolves links to bodies and frames,
/// assigns rows. Throws proxgen::Error naming the layout file and the constraint.
System bindLayout(Model model, const Layout& layout);

}  // namespace proxgen
