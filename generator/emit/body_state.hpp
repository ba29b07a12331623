// The symbolic quantities the emitter's passes hand each other: what each pass
// produces, per body, as expressions over workspace members and inputs (an
// expression is a value of one CodeBuilder: function.hpp moves the live ones
// from function to function). One struct per producing pass, so a pass's
// signature says what it reads (const references) and what it returns.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "emit/symbolic.hpp"

namespace proxgen::emit {

/// Kinematics pass (pass_kinematics.cpp): placements, velocities, the
/// constraint right-hand sides, and the inertia and bias the elimination starts from.
struct Kinematics {
  struct Body {
    XSym XT;            // tree placement (constant)
    XSym XJ;            // joint placement at q
    std::vector<V6> S;  // motion subspace columns (constant)
    V6 v = zero6(), c = zero6();
    V6 pA = zero6();    // v x* I v
    Sym IA{6};          // the body's own inertia (constant)
    V3 g = zero3();     // R_i^T g: gravity in body coordinates (support bodies)
    XSym oM;            // world placement (bodies under a kp constraint)
  };
  std::vector<Body> b;
  std::vector<std::vector<Expr>> k;  // per constraint: right-hand side k of K a = k
};

/// Articulated-body elimination (pass_aba_eliminate.cpp).
struct Articulated {
  struct Body {
    Sym IA{6};
    V6 pA = zero6();
    std::vector<V6> U;       // IA S, one column per dof
    Expr Dinv;               // 1 / (S^T IA S) for one-dof joints
    Sym L{6};                // Cholesky factor of D = S^T IA S (= IA for the free flyer; 3 x 3 for a planar joint)
    std::vector<Expr> Linv;  // its inverse diagonal
    std::vector<Expr> u;     // tau - S^T pA (+ multiplier terms in constrainedABA)
  };
  std::vector<Body> b;
};

/// Forward accelerations (pass_aba_accelerate.cpp).
struct Motion {
  std::vector<V6> a;        // per body (gravity-shifted)
  std::vector<Expr> qdd;    // nv
};

/// The multipliers (pass_constrained_aba.cpp, pass_prox_pv.cpp), layout order.
struct Multipliers {
  std::vector<Expr> lambda, dlambda;
};

/// constrainedABA's reduced sweep: the force increments per body.
struct Increments {
  std::vector<V6> dp;
};

/// proxPV's rows (pass_prox_pv.cpp): the constraint directions carried up the support.
struct ProxRows {
  struct Body {
    std::vector<V6> KA;                  // constraint force directions of the subtree rows
    std::vector<Expr> KSD;               // D^-1 S^T KA, per row (one-dof joints)
    std::vector<V6> Z;                   // L^-1 S^T KA, per row (free flyer, planar joint: the first nv entries)
    std::vector<std::vector<Expr>> KS;   // S^T KA, per row
  };
  std::vector<Body> b;
  std::vector<Expr> yfree;  // free row accelerations, tree order
};

/// The factor of G + I/mu (pass_delassus_factor.cpp).
struct DelassusFactor {
  Sym L;                  // factor of G + I/mu, or of its part A without the free flyer's
  std::vector<Expr> Linv;
  std::vector<V6> W;      // floating base: L^-1 Z^T (row t: 6 values)
  Sym LS{6};              // floating base: factor of I + W^T W
  std::vector<Expr> LSinv;
  /// A branch of the rows whose blocks meet in low rank (pass_delassus_factor.cpp):
  /// L(i, j) between two of its blocks is (g M_l)[i] . Y[j], not stored in L.
  struct Branch {
    std::vector<int> blocks;  // first row of each block (tree order), then the end
    int rank = 0;
    int y = 0, gm = 0;        // offsets in lowRank of Y[t][p] and (g M_l)[l][t][p]
  };
  std::vector<Branch> branches;
  std::vector<Expr> lowRank;  // the branches' stored terms
};

/// Inverse dynamics (pass_inverse_dynamics.cpp): per body its acceleration
/// and the force it passes to its parent; the joint torques.
struct Forces {
  std::vector<V6> a, f;
  std::vector<Expr> tau;
};

/// The joint-space matrices (pass_mass_matrix.cpp, pass_mass_matrix_inverse.cpp):
/// per body the composite inertia (CRBA) or the 6 x nv columns of unit-torque
/// forces, then accelerations (M^-1); the upper triangle of M or M^-1 (packed by rows).
struct JointSpace {
  std::vector<Rigid> Ic;  // composite inertias (CRBA)
  std::vector<std::vector<V6>> FA;
  std::vector<V6> carried;  // CRBA: column k in the frame of the body being visited
  Sym upper;
};

/// The constraint functions (pass_constraint_kinematics.cpp, pass_delassus.cpp):
/// the apparent inverse inertia of each support body (Delassus) and the
/// entries of the function's output, which its host copies out.
struct ConstraintOutputs {
  std::vector<Sym> Phi;
  std::vector<std::vector<Expr>> T;  // per body: a 6 x 6 map of the rows below (empty: none)
  std::vector<Expr> out;
};

/// The pass outputs in scope in the function being written: what moves into a
/// new part function at each boundary (null: not in scope). Visited body by
/// body in a fixed order, which fixes the order of the atoms in the new
/// function and so the order of the terms in the printed sums.
struct Live {
  Kinematics* kin = nullptr;
  Articulated* art = nullptr;
  Motion* motion = nullptr;
  Increments* inc = nullptr;
  ProxRows* rows = nullptr;
  Multipliers* mult = nullptr;
  DelassusFactor* del = nullptr;
  Forces* forces = nullptr;
  JointSpace* js = nullptr;
  ConstraintOutputs* cons = nullptr;  // visited last: the solvers' order is unchanged
};

void forEachExpr(Live& live, const std::function<void(Expr&)>& f);

}  // namespace proxgen::emit
