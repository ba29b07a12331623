// What every pass of the emitter shares: the inputs (System, Plan), the
// workspace-member registry, the function being written, and the few steps
// every recursion takes (a member store that skips constants, a body's block,
// moving a motion or force across a joint).
#pragma once

#include <string>
#include <vector>

#include "emit/body_state.hpp"
#include "emit/function.hpp"
#include "emit/members.hpp"
#include "emit/plan.hpp"

namespace proxgen::emit {

struct FreeAccelerations;

struct Emit {
  const System& sys;
  const Plan& plan;
  Members& ws;
  FunctionWriter& fn;
  FreeAccelerations* freeAccel = nullptr;  // the off-support accelerations, printed once (pass_aba_accelerate.cpp)

  const Model& model() const { return sys.model; }
  CodeBuilder& cb() { return fn.cb(); }
  const BodyPlan& bp(int i) const { return plan.bodies[std::size_t(i)]; }

  // ---- members
  std::string member(const std::string& base, int size, int idx, const std::string& comment) {
    return ws.member(base, size, idx, comment);
  }
  std::string member(const Quantity& qy, int body, int size, int idx);
  std::string loopSlot(const Quantity& qy, int body, int size, int idx);
  /// Entry (r, c) of a per-body rows x cols matrix member, and its slot (r, c + j) in a loop over j.
  std::string member(const Quantity& qy, int body, int rows, int cols, int r, int c);
  std::string loopSlot(const Quantity& qy, int body, int rows, int cols, int r, int c);
  std::string yMember(int t) { return member("yfree", plan.nc, t, "free row accelerations (tree order)"); }
  std::string kMember(int k, int j);
  std::string lambdaMember(int row) { return member("lambda", plan.nc, row, "multipliers (layout order)"); }
  /// member = e, unless e is a constant (then e itself).
  Expr put(const std::string& text, const Expr& e) { return e.isConstant() ? e : cb().store(text, e); }
  Expr putQ(const Quantity& qy, int body, int size, int idx, const Expr& e) {
    return e.isConstant() ? e : cb().store(member(qy, body, size, idx), e);
  }
  /// member = e, unless e is a constant or +-(an input or a member).
  Expr keep(const std::string& text, const Expr& e) {
    return e.isConstant() || cb().isAlias(e) ? e : cb().store(text, e);
  }
  Expr keepQ(const Quantity& qy, int body, int size, int idx, const Expr& e) {
    return e.isConstant() || cb().isAlias(e) ? e : cb().store(member(qy, body, size, idx), e);
  }
  /// The same for entry (r, c) of a rows x cols matrix member.
  Expr keepQ(const Quantity& qy, int body, int rows, int cols, int r, int c, const Expr& e) {
    return e.isConstant() || cb().isAlias(e) ? e : cb().store(member(qy, body, rows, cols, r, c), e);
  }

  // ---- structure
  std::vector<std::string> bodyComments(int i, const std::string& stage) const;
  void openBody(int i, const std::string& stage) { cb().open("{", bodyComments(i, stage)); }
  V6 rootAcceleration() const;
  /// Parent to child: through the tree placement, then the joint (X_i = X_J X_T).
  V6 motionToChild(const Kinematics::Body& b, const V6& m);
  V6 forceToParent(const Kinematics::Body& b, const V6& f);
  Sym inertiaToParent(const Kinematics::Body& b, const Sym& M);
  Rigid inertiaToParent(const Kinematics::Body& b, const Rigid& r);
  /// K x (K = the first rows of cXi) for constraint k.
  std::vector<Expr> constraintRows(int k, const V6& x);
};

/// The component S picks for a joint along +-x/y/z (3 + axis for a revolute,
/// axis for a prismatic joint), else -1.
int axisComponent(const BodyPlan& p);

/// Puts a pass output in scope (Live) while the pass writes it; the previous
/// one is back in scope when the guard ends.
template <class T>
class InScope {
 public:
  InScope(T*& slot, T* value) : slot_(slot), old_(slot) { slot_ = value; }
  ~InScope() { slot_ = old_; }
  InScope(const InScope&) = delete;
  InScope& operator=(const InScope&) = delete;

 private:
  T*& slot_;
  T* old_;
};

}  // namespace proxgen::emit
