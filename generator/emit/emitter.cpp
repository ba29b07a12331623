#include "emit/emitter.hpp"

#include <fmt/format.h>

#include <functional>
#include <memory>
#include <map>
#include <cctype>
#include <stdexcept>

#include "emit/identifiers.hpp"
#include "emit/symbolic.hpp"

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

// ------------------------------------------------------------------ state

// What the emitter knows about each body at the current point of the printed
// code: every quantity as an expression over workspace members and inputs.
struct BodySym {
  XSym XT;                 // tree placement (constant)
  XSym XJ;                 // joint placement at q
  std::vector<V6> S;       // motion subspace columns (constant)
  V6 v = zero6(), c = zero6(), a = zero6(), pA = zero6(), dp = zero6();
  V3 g = zero3();          // R_i^T g: gravity in body coordinates
  XSym oM;                 // world placement (bodies under a kp constraint)
  Sym IA{6};
  std::vector<V6> U;       // IA S, one column per dof
  Expr Dinv;               // 1 / (S^T IA S) for one-dof joints
  Sym L{6};                // Cholesky factor of IA for the free flyer (lower, off-diagonal)
  std::vector<Expr> Linv;  // its inverse diagonal
  std::vector<Expr> u;     // tau - S^T pA (+ multiplier terms in constrainedABA)
  std::vector<V6> KA;      // proxPV: constraint force directions of the subtree rows
  std::vector<Expr> KSD;   // proxPV: D^-1 S^T KA, per row (one-dof joints)
  std::vector<V6> Z;       // proxPV: L^-1 KA, per row (the free flyer)
  std::vector<std::vector<Expr>> KS;  // proxPV: S^T KA, per row
};

struct State {
  std::vector<BodySym> b;
  std::vector<std::vector<Expr>> k;  // per constraint: right-hand side k of K a = k
  std::vector<Expr> qdd, lambda, dlambda, yfree;
  Sym L;                             // factor of G + I/mu, or of its part A without the free flyer's
  std::vector<Expr> Linv;
  std::vector<V6> W;                 // floating base: L^-1 Z^T (row t: 6 values)
  Sym LS{6};                         // floating base: factor of I + W^T W
  std::vector<Expr> LSinv;
};

void forEachExpr(State& s, const std::function<void(Expr&)>& f) {
  auto v3 = [&](V3& x) { for (Expr& e : x) f(e); };
  auto v6 = [&](V6& x) { for (Expr& e : x) f(e); };
  auto sym = [&](Sym& m) { for (int k = 0; k < m.packedSize(); ++k) f(m.packed(k)); };
  auto vec = [&](std::vector<Expr>& x) { for (Expr& e : x) f(e); };
  auto xs = [&](XSym& X) {
    for (Expr& e : X.R) f(e);
    v3(X.p);
  };
  for (BodySym& b : s.b) {
    xs(b.XJ);
    xs(b.oM);
    v6(b.v), v6(b.c), v6(b.a), v6(b.pA), v6(b.dp), v3(b.g);
    sym(b.IA), sym(b.L);
    vec(b.KSD);
    for (V6& x : b.Z) v6(x);
    for (V6& x : b.U) v6(x);
    for (V6& x : b.KA) v6(x);
    for (auto& x : b.KS) vec(x);
    f(b.Dinv);
    vec(b.Linv), vec(b.u);
  }
  for (auto& x : s.k) vec(x);
  vec(s.qdd), vec(s.lambda), vec(s.dlambda), vec(s.yfree), vec(s.Linv), vec(s.LSinv);
  sym(s.L), sym(s.LS);
  for (V6& x : s.W) v6(x);
}

void translate(State& s, const CodeBuilder& from, CodeBuilder& to) {
  std::vector<int> cache;
  forEachExpr(s, [&](Expr& e) {
    if (!e.isConstant()) e = to.import(from, e, cache);
  });
}

// ------------------------------------------------------------------ members

struct Member {
  std::string name;
  int size = 0;  // 0: a scalar
  std::string comment;
};

// A per-body quantity: workspace member <prefix>_<ident>.
struct Quantity {
  const char* prefix;
  const char* what;
};
constexpr Quantity kQ{"q", "joint offset q"}, kSin{"sq", "sin q"}, kCos{"cq", "cos q"}, kRJ{"RJ", "joint rotation (row-major)"},
    kV{"v", "velocity"}, kC{"c", "velocity-product acceleration"}, kPA{"pA", "bias force"},
    kIA{"IA", "articulated inertia (upper triangle)"}, kG{"g", "gravity in body coordinates"},
    kOR{"oR", "world rotation"}, kOP{"op", "world position"}, kU{"U", "IA S"}, kDinv{"Dinv", "1 / (S^T IA S)"},
    kL{"L", "Cholesky factor of IA (lower, packed by rows of the upper)"}, kLinv{"Linv", "1 / diag(L)"},
    kUu{"u", "tau - S^T pA"}, kA{"a", "acceleration (gravity-shifted)"}, kDP{"dp", "reduced-sweep force"},
    kKA{"KA", "constraint force directions of the subtree rows (row-major: row r, column j at r (m + 1) + j)"},
    kKS{"KS", "S^T KA"}, kKSD{"KSD", "D^-1 S^T KA"}, kZ{"Z", "L^-1 KA (row-major)"},
    kK{"k", "constraint right-hand side"};

std::string q(int k) { return fmt::format("q[{}]", k); }
std::string vIn(int k) { return fmt::format("v[{}]", k); }
std::string tauIn(int k) { return fmt::format("tau[{}]", k); }

// The component S picks for a joint along +-x/y/z (3 + axis for a revolute,
// axis for a prismatic joint), else -1.
int axisComponent(const BodyPlan& p) {
  if (p.axis < 0) return -1;
  return p.axis + (p.jointClass <= JointClass::RevoluteAxis ? 3 : 0);
}

// ------------------------------------------------------------------ emitter

class Emitter {
 public:
  Emitter(const System& sys, const Plan& plan) : sys_(sys), plan_(plan), m_(sys.model) {}
  SolverFiles run(const SolverInputs& in, SolverStats* stats);

 private:
  // members
  std::string member(const std::string& base, int size, int idx, const std::string& comment);
  std::string member(const Quantity& qy, int body, int size, int idx);
  Expr put(const std::string& text, const Expr& e) { return e.isConstant() ? e : cb_->store(text, e); }
  Expr putQ(const Quantity& qy, int body, int size, int idx, const Expr& e) {
    return e.isConstant() ? e : cb_->store(member(qy, body, size, idx), e);
  }
  Expr keep(const std::string& text, const Expr& e) {
    return e.isConstant() || cb_->isAlias(e) ? e : cb_->store(text, e);
  }
  std::string yMember(int t) { return member("yfree", plan_.nc, t, "free row accelerations (tree order)"); }
  std::string kMember(int k, int j) {
    const ConstraintPlan& c = plan_.constraints[std::size_t(k)];
    return member("k_" + c.ident, c.rows, j, fmt::format("{}, constraint {}", kK.what, k));
  }
  Expr keepQ(const Quantity& qy, int body, int size, int idx, const Expr& e) {
    return e.isConstant() || cb_->isAlias(e) ? e : cb_->store(member(qy, body, size, idx), e);
  }

  // structure
  const BodyPlan& bp(int i) const { return plan_.bodies[std::size_t(i)]; }
  BodySym& bs(int i) { return st_.b[std::size_t(i)]; }
  std::vector<std::string> bodyComments(int i, const std::string& stage) const;
  void openBody(int i, const std::string& stage) { cb_->open("{", bodyComments(i, stage)); }
  V6 rootAcceleration() const;
  V6 motionToChild(int i, const V6& m);
  V6 forceToParent(int i, const V6& f);
  Sym inertiaToParent(int i, const Sym& M);
  std::vector<Expr> constraintRows(int k, const V6& x);  // K x (K = first rows of cXi)

  // kinematics function
  void jointTransform(int i);
  void velocity(int i);
  void gravityAndPlacement(int i);
  void constraintTerms(int k);

  // per-body steps
  void penalty(int i, Sym& IA, V6& pA);
  void eliminate(int i, bool caba);
  void eliminateOneDof(int i, bool caba);
  void eliminateFreeFlyer(int i, bool caba);
  void accelerate(int i, const std::vector<Expr>& uEff, bool storeQdd = true);
  void freeRowAccelerations();
  void pvRows(int i);
  void pvRowsOneDof(int i);
  int loopableColumns(int i, int c0);
  std::string loopSlot(const Quantity& qy, int body, int size, int idx);
  void pvRowsFreeFlyer(int i);

  // algebra
  struct Chol {
    Sym L;
    std::vector<Expr> inv;
  };
  Chol cholesky(const Sym& A, const Expr& shift, const std::function<std::string(int, int)>& Lname,
                const std::function<std::string(int)>& invName);
  std::vector<Expr> forwardSolve(const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& b);
  std::vector<Expr> backwardSolve(const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& y);

  // functions
  /// Slots per row of the row-major KA and Z: m columns and one unused slot.
  static int rowStride(int m) { return m + 1; }
  /// Runs of at least this many constraint columns that go through the same
  /// arithmetic are printed as a loop (README, "The generated solver").
  static constexpr int kLoopColumns = 4;
  static constexpr int kPartBudget = 40;  // statements per part (before dead-code removal): measured best
  struct Host {
    std::string name;
    CodeBuilder* cb = nullptr;
    int parts = 0;
  };
  void beginHost(const std::string& name);
  std::string endHost(const std::vector<std::string>& params);
  void boundary();
  void endPart();
  std::string render(CodeBuilder& cb);
  static bool reads(const std::string& body, const std::string& name);
  std::string emitKinematics();
  std::string emitEliminateFree();
  std::string emitAccelerateFree();
  std::string emitCaba();
  std::string emitPv();
  void updateMultipliers(bool first);
  void reducedSweep();
  std::string fingerprint(const std::vector<int>& bodies, bool withU) const;
  std::string accelerations(const std::vector<int>& bodies) const;
  void initRows();
  Expr delassus(int t, int u, bool withFreeFlyer);
  void delassusCholesky();
  int freeFlyerWithRows() const;
  void woodburyFactor(int ff);
  std::vector<Expr> delassusSolve(const std::vector<Expr>& rhs);
  void copyOut();
  void callAccelerateFree();

  const System& sys_;
  const Plan& plan_;
  const Model& m_;
  CodeBuilder* cb_ = nullptr;   // where statements go now (a part or a host)
  CodeBuilder* part_ = nullptr;
  Host host_;
  Expr hostMu_, hostInvMu_;     // the host's mu and 1/mu, passed to parts
  std::vector<std::unique_ptr<CodeBuilder>> builders_;  // all of them, alive for translations
  std::shared_ptr<NameTable> names_ = std::make_shared<NameTable>();
  std::string partsText_;
  State st_;
  std::vector<Member> members_;
  std::map<std::string, int> memberIndex_;
  CodeBuilder::Stats stats_;
  State afterAccel_;
  CodeBuilder* accelBuilder_ = nullptr;
  std::string supportAccelerations_, accelerateText_;
  std::vector<std::map<int, int>> rowsAt_;  // per Delassus row: body -> its column there
};

std::string Emitter::member(const std::string& base, int size, int idx, const std::string& comment) {
  auto it = memberIndex_.find(base);
  if (it == memberIndex_.end()) {
    memberIndex_[base] = int(members_.size());
    members_.push_back({base, size, comment});
  } else if (members_[std::size_t(it->second)].size != size) {
    throw std::logic_error("emitter: member " + base + " used with two sizes");
  }
  return size == 0 ? "w." + base : fmt::format("w.{}[{}]", base, idx);
}

std::string Emitter::member(const Quantity& qy, int body, int size, int idx) {
  const std::string base = fmt::format("{}_{}", qy.prefix, bp(body).ident);
  return member(base, size, idx, fmt::format("{}, body {}", qy.what, body));
}

std::vector<std::string> Emitter::bodyComments(int i, const std::string& stage) const {
  const BodyPlan& b = bp(i);
  const std::string parent = b.parent > 0 ? "'" + escapeComment(bp(b.parent).link) + "'" : "the world";
  return {fmt::format("{}body {} '{}': joint '{}' ({}), parent {}{}", stage.empty() ? "" : stage + " ", i, escapeComment(b.link),
                      escapeComment(b.joint), jointClassName(b.jointClass), parent,
                      b.onSupport ? "" : ", off the support")};
}

V6 Emitter::rootAcceleration() const {
  const Vec3 g = m_.gravity;
  return {Expr(-g[0]), Expr(-g[1]), Expr(-g[2]), Expr(), Expr(), Expr()};
}

// Parent to child: through the tree placement, then the joint (X_i = X_J X_T).
V6 Emitter::motionToChild(int i, const V6& m) {
  return actInvMotion(*cb_, bs(i).XJ, actInvMotion(*cb_, bs(i).XT, m));
}

V6 Emitter::forceToParent(int i, const V6& f) { return actForce(*cb_, bs(i).XT, actForce(*cb_, bs(i).XJ, f)); }

Sym Emitter::inertiaToParent(int i, const Sym& M) {
  return congruence(*cb_, bs(i).XT, congruence(*cb_, bs(i).XJ, M));
}

std::vector<Expr> Emitter::constraintRows(int k, const V6& x) {
  const Constraint& c = sys_.constraints[std::size_t(k)];
  const V6 y = actInvMotion(*cb_, constant(c.placement), x);
  return std::vector<Expr>(y.begin(), y.begin() + c.rows());
}

// ------------------------------------------------------------------ kinematics

void Emitter::jointTransform(int i) {
  BodySym& b = bs(i);
  const Body& body = m_.bodies[std::size_t(i)];
  const Joint& j = body.joint;
  const BodyPlan& p = bp(i);
  b.XT = constant(body.treePlacement);
  b.XJ = {constant(Mat3(Mat3::Identity())), zero3()};
  const Mat6X S = m_.motionSubspace(i);
  b.S.clear();
  for (int d = 0; d < j.nv; ++d) b.S.push_back(constant(Vec6(S.col(d))));
  CodeBuilder& cb = *cb_;
  if (p.jointClass == JointClass::FreeFlyer) {
    // q = [x y z qx qy qz qw]; R as Eigen's Quaternion::toRotationMatrix (unnormalised input used as given).
    const Expr x = cb.input(q(j.idx_q + 3)), y = cb.input(q(j.idx_q + 4)), z = cb.input(q(j.idx_q + 5)),
               w = cb.input(q(j.idx_q + 6));
    // 2 a b + s 2 c d, the products in this order (see mulAdd in symbolic.cpp).
    auto two = [&](const Expr& a, const Expr& b2, double s, const Expr& c, const Expr& d) {
      return 2.0 * mulAdd(cb, a, b2, s, c, d);
    };
    const M3 R = {1.0 - two(y, y, 1.0, z, z), two(x, y, -1.0, w, z), two(x, z, 1.0, w, y),
                  two(x, y, 1.0, w, z), 1.0 - two(x, x, 1.0, z, z), two(y, z, -1.0, w, x),
                  two(x, z, -1.0, w, y), two(y, z, 1.0, w, x), 1.0 - two(x, x, 1.0, y, y)};
    for (int k = 0; k < 9; ++k) b.XJ.R[std::size_t(k)] = keepQ(kRJ, i, 9, k, R[std::size_t(k)]);
    b.XJ.p = {cb.input(q(j.idx_q)), cb.input(q(j.idx_q + 1)), cb.input(q(j.idx_q + 2))};
    return;
  }
  const Vec3 a = j.axis;
  if (j.type == JointType::Prismatic) {
    // Kept in the workspace: the backward and forward passes (other functions) need it.
    const Expr qi = cb.store(member(kQ, i, 0, 0), cb.input(q(j.idx_q)));
    for (int k = 0; k < 3; ++k) b.XJ.p[std::size_t(k)] = a[k] * qi;
    return;
  }
  // Revolute: R = c I + s [a]x + (1 - c) a a^T; an axis along +-x/y/z folds to picks of c and s.
  const std::string sm = member(kSin, i, 0, 0), cm = member(kCos, i, 0, 0);
  const std::vector<Expr> sc =
      cb.storeByCall(fmt::format("proxgen_rt::sincos({}, {}, {});", q(j.idx_q), sm, cm), {sm, cm}, {cb.input(q(j.idx_q))});
  const Expr &s = sc[0], &c = sc[1];
  const Mat3 K = skew(a), A = a * a.transpose();
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) {
      const Expr e = A(r, col) + (r == col ? 1.0 : 0.0) * c - A(r, col) * c + K(r, col) * s;
      b.XJ.R[std::size_t(3 * r + col)] = p.axis >= 0 ? e : keepQ(kRJ, i, 9, 3 * r + col, e);
    }
}

void Emitter::velocity(int i) {
  BodySym& b = bs(i);
  const Joint& j = m_.bodies[std::size_t(i)].joint;
  CodeBuilder& cb = *cb_;
  V6 vJ = zero6();
  for (int d = 0; d < j.nv; ++d) vJ = add(vJ, scale(cb, cb.input(vIn(j.idx_v + d)), b.S[std::size_t(d)]));
  const V6 v = add(motionToChild(i, bs(bp(i).parent).v), vJ);
  for (int k = 0; k < 6; ++k) b.v[std::size_t(k)] = keepQ(kV, i, 6, k, v[std::size_t(k)]);
  const V6 c = crossMotion(cb, b.v, vJ);
  for (int k = 0; k < 6; ++k) b.c[std::size_t(k)] = keepQ(kC, i, 6, k, c[std::size_t(k)]);
  // pA = v x* (I v); IA starts as the body's own inertia (a constant).
  b.IA = constant(m_.bodies[std::size_t(i)].inertia.matrix());
  V6 h = mul(cb, b.IA, b.v);
  flatten(cb, h, "h");
  const V6 pA = crossForce(cb, b.v, h);
  for (int k = 0; k < 6; ++k) b.pA[std::size_t(k)] = putQ(kPA, i, 6, k, pA[std::size_t(k)]);
}

void Emitter::gravityAndPlacement(int i) {
  BodySym& b = bs(i);
  const BodySym& parent = bs(bp(i).parent);
  if (bp(i).needsGravity) {
    const V3 g = rotateT(*cb_, b.XJ.R, rotateT(*cb_, b.XT.R, parent.g));
    for (int k = 0; k < 3; ++k) b.g[std::size_t(k)] = keepQ(kG, i, 3, k, g[std::size_t(k)]);
  }
  if (bp(i).needsPlacement) {
    const XSym M = compose(*cb_, compose(*cb_, parent.oM, b.XT), b.XJ);
    for (int k = 0; k < 9; ++k) b.oM.R[std::size_t(k)] = keepQ(kOR, i, 9, k, cb_->flat(M.R[std::size_t(k)]));
    for (int k = 0; k < 3; ++k) b.oM.p[std::size_t(k)] = keepQ(kOP, i, 3, k, cb_->flat(M.p[std::size_t(k)]));
  }
}

// k = a_star - drift - K X_{i,0} a_g (ALGORITHMS.md 2), as constraints.cpp computes it.
void Emitter::constraintTerms(int k) {
  const Constraint& c = sys_.constraints[std::size_t(k)];
  const ConstraintPlan& cp = plan_.constraints[std::size_t(k)];
  const BodySym& b = bs(c.body);
  CodeBuilder& cb = *cb_;
  const int r = c.rows();
  cb.comment(fmt::format("constraint '{}' ({}) on link '{}': rows {}..{}", escapeComment(c.name), cp.weld ? "6d" : "3d",
                         escapeComment(c.link), c.row, c.row + r - 1));
  const V6 vC = actInvMotion(cb, constant(c.placement), b.v);  // twist of the constraint frame
  std::vector<Expr> kk(static_cast<std::size_t>(r));
  if (c.kd != 0)
    for (int j = 0; j < r; ++j) kk[std::size_t(j)] -= c.kd * vC[std::size_t(j)];
  if (c.kp != 0) {
    const XSym oMc = compose(cb, b.oM, constant(c.placement));
    std::vector<Expr> err(static_cast<std::size_t>(r));
    if (cp.weld) {
      // log6(target^-1 oMc) through the runtime.
      const XSym E = compose(cb, constant(c.target.inverse()), oMc);
      std::vector<Expr> R, p;
      std::string Rs, ps;
      for (int j = 0; j < 9; ++j) {
        R.push_back(cb.flat(E.R[std::size_t(j)]));
        Rs += (j ? ", " : "") + cb.print(R.back());
      }
      for (int j = 0; j < 3; ++j) {
        p.push_back(cb.flat(E.p[std::size_t(j)]));
        ps += (j ? ", " : "") + cb.print(p.back());
      }
      std::vector<Expr> uses = R;
      uses.insert(uses.end(), p.begin(), p.end());
      const std::string id = cp.ident;
      cb.line(fmt::format("const Scalar kpR_{}[9] = {{{}}};", id, Rs), uses);
      cb.line(fmt::format("const Scalar kpp_{}[3] = {{{}}};", id, ps), uses);
      cb.line(fmt::format("Scalar kpe_{}[6];", id));
      cb.line(fmt::format("proxgen_rt::log6(kpR_{0}, kpp_{0}, kpe_{0});", id));
      for (int j = 0; j < 6; ++j) err[std::size_t(j)] = cb.input(fmt::format("kpe_{}[{}]", id, j));
    } else {
      V3 d;
      for (int j = 0; j < 3; ++j) d[std::size_t(j)] = oMc.p[std::size_t(j)] - c.target.p[j];
      const V3 e = rotateT(cb, oMc.R, d);
      err.assign(e.begin(), e.end());
    }
    for (int j = 0; j < r; ++j) kk[std::size_t(j)] -= c.kp * err[std::size_t(j)];
  }
  if (!cp.weld) {
    const V3 drift = cross(cb, ang(vC), lin(vC));  // w_C x v_C
    for (int j = 0; j < 3; ++j) kk[std::size_t(j)] -= drift[std::size_t(j)];
  }
  const std::vector<Expr> Kg = constraintRows(k, stack(b.g, zero3()));
  st_.k[std::size_t(k)].resize(std::size_t(r));
  for (int j = 0; j < r; ++j)
    st_.k[std::size_t(k)][std::size_t(j)] = keep(kMember(k, j), kk[std::size_t(j)] - Kg[std::size_t(j)]);
}

// ------------------------------------------------------------------ algebra

Emitter::Chol Emitter::cholesky(const Sym& A, const Expr& shift, const std::function<std::string(int, int)>& Lname,
                                const std::function<std::string(int)>& invName) {
  CodeBuilder& cb = *cb_;
  const int n = A.size();
  Chol ch{Sym(n), std::vector<Expr>(std::size_t(n))};
  for (int j = 0; j < n; ++j) {
    Expr d = A(j, j) + shift;
    for (int k = 0; k < j; ++k) d -= cb.mul(ch.L(j, k), ch.L(j, k));
    const Expr r = cb.sqrt(d, "r");
    ch.inv[std::size_t(j)] = put(invName(j), cb.recip(r, "inv"));
    for (int i = j + 1; i < n; ++i) {
      Expr e = A(i, j);
      for (int k = 0; k < j; ++k) e -= cb.mul(ch.L(i, k), ch.L(j, k));
      ch.L(i, j) = put(Lname(i, j), cb.mul(cb.flat(e), ch.inv[std::size_t(j)]));
    }
  }
  return ch;
}

std::vector<Expr> Emitter::forwardSolve(const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& b) {
  CodeBuilder& cb = *cb_;
  const int n = L.size();
  std::vector<Expr> y(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Expr e = b[std::size_t(i)];
    for (int k = 0; k < i; ++k) e -= cb.mul(L(i, k), y[std::size_t(k)]);
    y[std::size_t(i)] = cb.flat(cb.mul(cb.flat(e), inv[std::size_t(i)]), "y");
  }
  return y;
}

std::vector<Expr> Emitter::backwardSolve(const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& y) {
  CodeBuilder& cb = *cb_;
  const int n = L.size();
  std::vector<Expr> x(static_cast<std::size_t>(n));
  for (int i = n - 1; i >= 0; --i) {
    Expr e = y[std::size_t(i)];
    for (int k = i + 1; k < n; ++k) e -= cb.mul(L(k, i), x[std::size_t(k)]);
    x[std::size_t(i)] = cb.flat(cb.mul(cb.flat(e), inv[std::size_t(i)]), "x");
  }
  return x;
}

// ------------------------------------------------------------------ backward

// IA_i += mu K^T K ; pA_i -= mu K^T k for every constraint on body i.
void Emitter::penalty(int i, Sym& IA, V6& pA) {
  CodeBuilder& cb = *cb_;
  const Expr mu = cb_->input("mu");
  for (int k : bp(i).constraints) {
    const Constraint& c = sys_.constraints[std::size_t(k)];
    const Mat6 X = c.placement.motionMatrixInv();
    const auto K = X.topRows(c.rows());
    const Mat6 KtK = K.transpose() * K;
    for (int r = 0; r < 6; ++r)
      for (int col = r; col < 6; ++col) IA(r, col) += KtK(r, col) * mu;
    for (int r = 0; r < 6; ++r) {
      Expr Ktk;
      for (int j = 0; j < c.rows(); ++j) Ktk += K(j, r) * st_.k[std::size_t(k)][std::size_t(j)];
      pA[std::size_t(r)] -= cb.mul(mu, Ktk);
    }
  }
}

void Emitter::eliminate(int i, bool caba) {
  if (bp(i).jointClass == JointClass::FreeFlyer) eliminateFreeFlyer(i, caba);
  else eliminateOneDof(i, caba);
}

void Emitter::eliminateOneDof(int i, bool caba) {
  CodeBuilder& cb = *cb_;
  BodySym& b = bs(i);
  const BodyPlan& p = bp(i);
  Sym IA = b.IA;
  V6 pA = b.pA;
  if (caba) penalty(i, IA, pA);
  const V6& S = b.S[0];
  V6 U;
  for (int r = 0; r < 6; ++r)
    for (int k = 0; k < 6; ++k) U[std::size_t(r)] += cb.mul(IA(r, k), S[std::size_t(k)]);
  b.U.assign(1, V6{});
  for (int r = 0; r < 6; ++r) b.U[0][std::size_t(r)] = keepQ(kU, i, 6, r, U[std::size_t(r)]);
  const Expr D = cb.flat(dot(cb, S, b.U[0]), "D");
  b.Dinv = cb.storeRaw(member(kDinv, i, 0, 0), cb.literal(1.0) + " / " + cb.print(D), {D});
  const Expr tau = cb.input(tauIn(p.idx_v));  // before the products: see mulAdd in symbolic.cpp
  b.u.assign(1, putQ(kUu, i, 1, 0, tau - dot(cb, S, pA)));
  if (p.parent == 0) return;
  // Ia = IA - U D^-1 U^T (its row and column along an axis-aligned S vanish:
  // Ia S = 0) ; pa = pA + Ia c + U D^-1 u.
  V6 UD;
  for (int r = 0; r < 6; ++r) UD[std::size_t(r)] = cb.flat(cb.mul(b.U[0][std::size_t(r)], b.Dinv), "UD");
  Sym Ia(6);
  for (int r = 0; r < 6; ++r)
    for (int col = r; col < 6; ++col) Ia(r, col) = IA(r, col) - cb.mul(UD[std::size_t(r)], b.U[0][std::size_t(col)]);
  if (const int along = axisComponent(p); along >= 0)
    for (int k = 0; k < 6; ++k) Ia(along, k) = Expr();
  flatten(cb, Ia, "Ia");
  V6 pa;
  for (int r = 0; r < 6; ++r) {
    Expr e = pA[std::size_t(r)] + cb.mul(UD[std::size_t(r)], b.u[0]);
    for (int k = 0; k < 6; ++k) e += cb.mul(Ia(r, k), b.c[std::size_t(k)]);
    pa[std::size_t(r)] = e;
  }
  flatten(cb, pa, "pa");
  const Sym dI = inertiaToParent(i, Ia);
  const V6 dp = forceToParent(i, pa);
  BodySym& par = bs(p.parent);
  for (int k = 0; k < 21; ++k)
    if (!dI.packed(k).isZero()) par.IA.packed(k) = putQ(kIA, p.parent, 21, k, par.IA.packed(k) + dI.packed(k));
  for (int k = 0; k < 6; ++k)
    if (!dp[std::size_t(k)].isZero())
      par.pA[std::size_t(k)] = putQ(kPA, p.parent, 6, k, par.pA[std::size_t(k)] + dp[std::size_t(k)]);
}

// The free flyer: S = I, so U = IA and D = IA, factored once (LL^T); its
// parent is the world, so nothing passes on.
void Emitter::eliminateFreeFlyer(int i, bool caba) {
  CodeBuilder& cb = *cb_;
  BodySym& b = bs(i);
  const BodyPlan& p = bp(i);
  if (p.parent != 0) throw std::logic_error("emitter: a free flyer below another body");
  V6 pA = b.pA;
  if (caba) {
    penalty(i, b.IA, pA);
    for (int k = 0; k < 21; ++k) b.IA.packed(k) = keepQ(kIA, i, 21, k, b.IA.packed(k));
  }
  const Chol ch = cholesky(
      b.IA, Expr(), [&](int r, int c) { return member(kL, i, 21, Sym::index(6, r, c)); },
      [&](int r) { return member(kLinv, i, 6, r); });
  b.L = ch.L;
  b.Linv = ch.inv;
  b.U.assign(6, V6{});
  for (int d = 0; d < 6; ++d)
    for (int r = 0; r < 6; ++r) b.U[std::size_t(d)][std::size_t(r)] = b.IA(r, d);
  b.u.resize(6);
  for (int d = 0; d < 6; ++d)
    b.u[std::size_t(d)] = putQ(kUu, i, 6, d, cb.input(tauIn(p.idx_v + d)) - pA[std::size_t(d)]);
}

// ------------------------------------------------------------------ forward

// a'_i = X_i a_p + c_i ; qdd_i = D^-1 (u_i - U^T a'_i) ; a_i = a'_i + S qdd_i,
// with uEff the u to use (proxPV subtracts its multiplier terms).
void Emitter::accelerate(int i, const std::vector<Expr>& uEff, bool storeQdd) {
  CodeBuilder& cb = *cb_;
  BodySym& b = bs(i);
  const BodyPlan& p = bp(i);
  V6 ap = add(motionToChild(i, p.parent == 0 ? rootAcceleration() : bs(p.parent).a), b.c);
  flatten(cb, ap, "t");  // used twice: in U^T a' and in a
  const int n = p.nv;
  std::vector<Expr> r(static_cast<std::size_t>(n));
  for (int d = 0; d < n; ++d) r[std::size_t(d)] = uEff[std::size_t(d)] - dot(cb, b.U[std::size_t(d)], ap);
  std::vector<Expr> qdd(static_cast<std::size_t>(n));
  if (n == 1) qdd[0] = cb.mul(b.Dinv, cb.flat(r[0]));
  else qdd = backwardSolve(b.L, b.Linv, forwardSolve(b.L, b.Linv, r));
  V6 a = ap;
  for (int d = 0; d < n; ++d) {
    if (storeQdd)
      st_.qdd[std::size_t(p.idx_v + d)] = qdd[std::size_t(d)] =
          put(member("qdd", plan_.nv, p.idx_v + d, "joint accelerations"), qdd[std::size_t(d)]);
    a = add(a, scale(cb, qdd[std::size_t(d)], b.S[std::size_t(d)]));
  }
  const bool needed = !p.children.empty() || !p.constraints.empty();
  for (int k = 0; k < 6; ++k) b.a[std::size_t(k)] = needed ? putQ(kA, i, 6, k, a[std::size_t(k)]) : a[std::size_t(k)];
}

// ------------------------------------------------------------------ proxPV rows

void Emitter::pvRows(int i) {
  if (bp(i).m() == 0) return;
  if (bp(i).jointClass == JointClass::FreeFlyer) pvRowsFreeFlyer(i);
  else pvRowsOneDof(i);
}

// KS = S^T KA ; KA_p[cols] = X^T (KA - U D^-1 KS). The LA recursion
// (LA_p[block] = LA + KS^T D^-1 KS) sums up the tree to the Delassus matrix
// G = sum over the support of KS^T D^-1 KS at each body's rows: emitPv
// assembles it from KS and KSD = D^-1 KS. The lA recursion gives the rows'
// free accelerations y_free = K a_free - k: emitPv takes them from a forward
// pass with lambda = 0 instead (fewer products for many rows).
// KA is stored row-major: each column goes through the same arithmetic with
// the same coefficients, so with a row's columns adjacent in memory the
// compiler packs 2 or 4 columns into one vector instruction (SLP). A row of m
// columns takes m + 1 slots (rowStride): the unused slot keeps the stores of
// two rows, which differ in their arithmetic, out of one store group.
void Emitter::pvRowsOneDof(int i) {
  CodeBuilder& cb = *cb_;
  BodySym& b = bs(i);
  const BodyPlan& p = bp(i);
  const int m = p.m(), off = p.offsetInParent;
  const V6& S = b.S[0];
  const int along = axisComponent(p);
  const bool passes = p.parent != 0;  // KA_0 only met the root acceleration, in y_free
  V6 UD;
  if (passes)
    for (int r = 0; r < 6; ++r) UD[std::size_t(r)] = cb.flat(cb.mul(b.U[0][std::size_t(r)], b.Dinv), "UD");
  b.KS.assign(std::size_t(m), std::vector<Expr>(1));
  b.KSD.resize(std::size_t(m));
  auto plain = [&](const Expr& e) { return e.isConstant() || cb.isAlias(e); };  // nothing to store
  // One column: KS, KSD, and (below the root) its column of the parent's KA.
  // `ka` reads the column, `at` names the column's slot of this body's KS or
  // KSD ("[c0 + j]" in a loop over j, "[c]" unrolled).
  auto column = [&](const V6& ka, const std::function<std::string(const Quantity&)>& at) {
    struct Out {
      Expr ks, ksd;
      V6 f;
      bool ksdStored = false;
    } out;
    const Expr ks = dot(cb, S, ka);
    out.ks = plain(ks) ? ks : cb.store(at(kKS), ks);
    const Expr ksd = cb.mul(b.Dinv, out.ks);
    out.ksdStored = !plain(ksd);
    out.ksd = out.ksdStored ? cb.store(at(kKSD), ksd) : ksd;
    if (!passes) return out;
    V6 col;
    for (int r = 0; r < 6; ++r) col[std::size_t(r)] = ka[std::size_t(r)] - cb.mul(UD[std::size_t(r)], out.ks);
    if (along >= 0) col[std::size_t(along)] = Expr();  // S^T (KA - U D^-1 KS) = 0
    out.f = forceToParent(i, col);
    return out;
  };
  const int stride = rowStride(m), mp = passes ? bp(p.parent).m() : 0, pstride = rowStride(mp);
  BodySym& par = bs(p.parent);
  for (int c0 = 0; c0 < m;) {
    const int len = loopableColumns(i, c0);
    if (len >= kLoopColumns) {
      // Columns c0 .. c0 + len - 1 go through identical arithmetic: one loop
      // (vectorised by the compiler) instead of len copies of the code.
      cb.open(fmt::format("for (int j = 0; j < {}; ++j) {{", len), {fmt::format("columns {} to {}", c0, c0 + len - 1)});
      V6 ka;
      for (int r = 0; r < 6; ++r) ka[std::size_t(r)] = cb.member(loopSlot(kKA, i, 6 * stride, r * stride + c0));
      const auto out = column(ka, [&](const Quantity& qy) { return loopSlot(qy, i, m, c0); });
      if (passes)
        for (int r = 0; r < 6; ++r)
          cb.store(loopSlot(kKA, p.parent, 6 * pstride, r * pstride + off + c0), out.f[std::size_t(r)]);
      if (!out.ksdStored) throw std::logic_error("emitter: a looped column's D^-1 KS is not stored");
      cb.close();
      for (int c = c0; c < c0 + len; ++c) {
        const auto cu = std::size_t(c);
        const Expr ks = dot(cb, S, b.KA[cu]);  // the loop's KS for column c: a pick of KA prints nothing
        b.KS[cu][0] = plain(ks) ? ks : cb.member(member(kKS, i, m, c));
        b.KSD[cu] = cb.member(member(kKSD, i, m, c));
        if (passes)
          for (int r = 0; r < 6; ++r)
            par.KA[std::size_t(off + c)][std::size_t(r)] = cb.member(member(kKA, p.parent, 6 * pstride, r * pstride + off + c));
      }
      c0 += len;
      continue;
    }
    const auto out = column(b.KA[std::size_t(c0)], [&](const Quantity& qy) { return member(qy, i, m, c0); });
    b.KS[std::size_t(c0)][0] = out.ks;
    b.KSD[std::size_t(c0)] = out.ksd;
    if (passes)
      for (int r = 0; r < 6; ++r)
        par.KA[std::size_t(off + c0)][std::size_t(r)] =
            putQ(kKA, p.parent, 6 * pstride, r * pstride + off + c0, out.f[std::size_t(r)]);
    ++c0;
  }
}

// How many columns from c0 on hold exactly the members KA_i[r * stride + c]
// (each entry stored, none folded): a loop over them reads the same slots.
int Emitter::loopableColumns(int i, int c0) {
  const BodySym& b = bs(i);
  const int m = bp(i).m(), stride = rowStride(m);
  int c = c0;
  for (; c < m; ++c) {
    bool canonical = true;
    for (int r = 0; r < 6 && canonical; ++r) {
      const Expr& e = b.KA[std::size_t(c)][std::size_t(r)];
      canonical = e.isScaledAtom() && e.terms()[0].coeff == 1.0 &&
                  e.terms()[0].atom == cb_->member(member(kKA, i, 6 * stride, r * stride + c)).terms()[0].atom;
    }
    if (!canonical) break;
  }
  return c - c0;
}

// Slot idx + j of a per-body array member (j: the loop variable).
std::string Emitter::loopSlot(const Quantity& qy, int body, int size, int idx) {
  const std::string first = member(qy, body, size, idx);  // declares the member
  return idx == 0 ? first.substr(0, first.size() - 2) + "j]" : first.substr(0, first.size() - 1) + " + j]";
}

// At the free flyer (S = I, D = IA = L L^T, parent the world, KA_0 = 0):
// its share of G is Z^T Z with Z = L^-1 KA.
void Emitter::pvRowsFreeFlyer(int i) {
  BodySym& b = bs(i);
  const int m = bp(i).m();
  b.KS.assign(std::size_t(m), std::vector<Expr>(6));
  for (int j = 0; j < m; ++j)
    for (int d = 0; d < 6; ++d) b.KS[std::size_t(j)][std::size_t(d)] = b.KA[std::size_t(j)][std::size_t(d)];
  b.Z.resize(std::size_t(m));
  for (int j = 0; j < m; ++j) {
    const std::vector<Expr> z =
        forwardSolve(b.L, b.Linv, std::vector<Expr>(b.KA[std::size_t(j)].begin(), b.KA[std::size_t(j)].end()));
    for (int d = 0; d < 6; ++d)
      b.Z[std::size_t(j)][std::size_t(d)] = keepQ(kZ, i, 6 * rowStride(m), d * rowStride(m) + j, z[std::size_t(d)]);
  }
}

// y_free = K a_free - k: the rows' accelerations with lambda = 0, from a
// forward pass over the support (a_i members are rewritten by the final pass).
void Emitter::freeRowAccelerations() {
  for (int i : plan_.support) {
    boundary();
    openBody(i, "free acceleration (lambda = 0):");
    accelerate(i, bs(i).u, false);
    cb_->close();
  }
  std::vector<int> position(static_cast<std::size_t>(plan_.nc));
  for (int t = 0; t < plan_.nc; ++t) position[std::size_t(plan_.rootRows[std::size_t(t)])] = t;
  boundary();
  cb_->open("{", {"free row accelerations y_free = K a - k (tree order)"});
  for (std::size_t k = 0; k < sys_.constraints.size(); ++k) {
    const Constraint& c = sys_.constraints[k];
    const std::vector<Expr> Ka = constraintRows(int(k), c.body == 0 ? rootAcceleration() : bs(c.body).a);
    for (int j = 0; j < c.rows(); ++j) {
      const int t = position[std::size_t(c.row + j)];
      st_.yfree[std::size_t(t)] = put(yMember(t), Ka[std::size_t(j)] - st_.k[k][std::size_t(j)]);
    }
  }
  cb_->close();
}

// ------------------------------------------------------------------ functions

// The body of a host function (kinematics, constrained_aba, ...) is a list of
// calls to part functions, each holding a few bodies' blocks: small functions
// keep the compiler's time linear in the robot's size.
void Emitter::beginHost(const std::string& name) {
  auto cb = std::make_unique<CodeBuilder>(plan_.scalar, names_);
  if (cb_) translate(st_, *cb_, *cb);
  cb_ = cb.get();
  host_ = {name, cb.get(), 0};
  builders_.push_back(std::move(cb));
}

void Emitter::boundary() {
  if (part_ && part_->statementCount() >= kPartBudget) endPart();
  if (part_) return;
  auto cb = std::make_unique<CodeBuilder>(plan_.scalar, names_);
  translate(st_, *cb_, *cb);
  cb_ = part_ = cb.get();
  builders_.push_back(std::move(cb));
}

std::string Emitter::render(CodeBuilder& cb) {
  const CodeBuilder::Stats st = cb.stats();
  stats_.statements += st.statements;
  stats_.temporaries += st.temporaries;
  stats_.multiplies += st.multiplies;
  return cb.render(2);
}

// Whether code (not its // comments: the generated files have no string
// literals) names the identifier `name`.
bool Emitter::reads(const std::string& body, const std::string& name) {
  auto ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (std::size_t k = 0; k < body.size(); ++k) {
    if (body.compare(k, 2, "//") == 0) {
      k = body.find('\n', k);
      if (k == std::string::npos) return false;
      continue;
    }
    if (body.compare(k, name.size(), name) == 0 && (k == 0 || !ident(body[k - 1])) &&
        (k + name.size() == body.size() || !ident(body[k + name.size()])))
      return true;
  }
  return false;
}

void Emitter::endPart() {
  if (!part_) return;
  const std::string body = render(*part_);
  const bool empty = body.find_first_not_of(" \n") == std::string::npos;
  const std::string name = fmt::format("{}_{}", host_.name, empty ? -1 : host_.parts++);
  std::vector<std::string> params, args;
  std::vector<Expr> uses;
  for (const char* p : {"q", "v", "tau"})
    if (reads(body, p)) {
      params.push_back(fmt::format("const Scalar* PROXGEN_RT_RESTRICT {}", p));
      args.push_back(p);
    }
  for (const char* p : {"mu", "inv_mu"})
    if (reads(body, p)) {
      params.push_back(fmt::format("Scalar {}", p));
      args.push_back(p);
      uses.push_back(std::string(p) == "mu" ? hostMu_ : hostInvMu_);
    }
  if (reads(body, "w")) {
    params.push_back("Workspace& PROXGEN_RT_RESTRICT w");
    args.push_back("w");
  }
  std::string sig, call;
  for (std::size_t k = 0; k < params.size(); ++k) {
    sig += (k ? ", " : "") + params[k];
    call += (k ? ", " : "") + args[k];
  }
  translate(st_, *part_, *host_.cb);
  cb_ = host_.cb;
  part_ = nullptr;
  if (empty) return;  // everything folded to constants: no function
  partsText_ += fmt::format("PROXGEN_RT_NOINLINE void {}({}) noexcept {{\n{}}}\n\n", name, sig, body);
  cb_->line(fmt::format("{}({});", name, call), uses);
}

std::string Emitter::endHost(const std::vector<std::string>& params) {
  endPart();
  std::string body = render(*host_.cb);
  // A parameter the body never reads (no constraints, no joints) is marked used.
  std::string prefix;
  for (const std::string& p : params)
    if (!reads(body, p)) prefix += "  static_cast<void>(" + p + ");\n";
  return prefix + body;
}

std::string Emitter::emitKinematics() {
  beginHost("kinematics");
  // World: at rest, gravity as given, at the origin.
  BodySym& w = bs(0);
  w.g = constant(m_.gravity);
  w.oM = constant(SE3::Identity());
  for (int i = 1; i < m_.numBodies(); ++i) {
    boundary();
    openBody(i, "");
    jointTransform(i);
    velocity(i);
    gravityAndPlacement(i);
    for (int k : bp(i).constraints) constraintTerms(k);
    cb_->close();
  }
  if (!bp(0).constraints.empty()) {
    boundary();
    cb_->open("{", {"constraints on the world"});
    for (int k : bp(0).constraints) constraintTerms(k);
    cb_->close();
  }
  return endHost({"q", "v", "w"});
}

std::string Emitter::emitEliminateFree() {
  beginHost("eliminate_free");
  for (auto it = plan_.offSupport.rbegin(); it != plan_.offSupport.rend(); ++it) {
    boundary();
    openBody(*it, "eliminate");
    eliminate(*it, false);
    cb_->close();
  }
  return endHost({"tau", "w"});
}

std::string Emitter::emitAccelerateFree() {
  beginHost("accelerate_free");
  for (int i : plan_.offSupport) {
    boundary();
    openBody(i, "accelerate");
    accelerate(i, bs(i).u);
    cb_->close();
  }
  return endHost({"w"});
}

std::string Emitter::fingerprint(const std::vector<int>& bodies, bool withU) const {
  std::string f;
  auto add = [&](const Expr& e) { f += cb_->describe(e) + ";"; };
  for (int i : bodies) {
    for (const Expr& e : st_.b[std::size_t(i)].a) add(e);
    if (withU)
      for (const Expr& e : st_.b[std::size_t(i)].u) add(e);
  }
  for (const Expr& e : st_.lambda) add(e);
  for (const Expr& e : st_.dlambda) add(e);
  return f;
}

std::string Emitter::accelerations(const std::vector<int>& bodies) const {
  std::string f;
  for (int i : bodies)
    for (const Expr& e : st_.b[std::size_t(i)].a) f += cb_->describe(e) + ";";
  return f;
}

// lambda += mu (K a - k) for every constraint, keeping the increment for the next sweep.
void Emitter::updateMultipliers(bool first) {
  boundary();
  CodeBuilder& cb = *cb_;
  cb.open("{", {"multiplier update: dlambda = mu (K a - k), lambda += dlambda"});
  for (std::size_t k = 0; k < sys_.constraints.size(); ++k) {
    const Constraint& c = sys_.constraints[k];
    const std::vector<Expr> Ka = constraintRows(int(k), c.body == 0 ? rootAcceleration() : bs(c.body).a);
    for (int j = 0; j < c.rows(); ++j) {
      const int row = c.row + j;
      const Expr mu = cb.input("mu");  // before the difference's temporary: see mulAdd in symbolic.cpp
      const Expr dl = cb.mul(mu, cb.flat(Ka[std::size_t(j)] - st_.k[k][std::size_t(j)]));
      st_.dlambda[std::size_t(row)] = put(member("dlambda", plan_.nc, row, "latest multiplier increment"), dl);
      st_.lambda[std::size_t(row)] = put(member("lambda", plan_.nc, row, "multipliers (layout order)"),
                                         first ? st_.dlambda[std::size_t(row)]
                                               : st_.lambda[std::size_t(row)] + st_.dlambda[std::size_t(row)]);
    }
  }
  cb.close();
}

// Iterations 2..K of constrainedABA: IA, U, D stay; the bias moves linearly in
// the latest increment, on the support only (ALGORITHMS.md 4.1).
void Emitter::reducedSweep() {
  for (int i : plan_.support) bs(i).dp = zero6();
  for (auto it = plan_.support.rbegin(); it != plan_.support.rend(); ++it) {
    const int i = *it;
    boundary();
    CodeBuilder& cb = *cb_;
    BodySym& b = bs(i);
    const BodyPlan& p = bp(i);
    openBody(i, "reduced sweep:");
    V6 dp = b.dp;
    for (int k : p.constraints) {
      const Constraint& c = sys_.constraints[std::size_t(k)];
      const Mat6 X = c.placement.motionMatrixInv();
      for (int r = 0; r < 6; ++r)
        for (int j = 0; j < c.rows(); ++j) dp[std::size_t(r)] += X(j, r) * st_.dlambda[std::size_t(c.row + j)];
    }
    if (p.jointClass == JointClass::FreeFlyer) {
      for (int d = 0; d < 6; ++d)
        b.u[std::size_t(d)] = cb.store(member(kUu, i, 6, d), b.u[std::size_t(d)] - dp[std::size_t(d)]);
    } else {
      const Expr du = cb.flat(-dot(cb, b.S[0], dp), "du");
      b.u[0] = cb.store(member(kUu, i, 1, 0), b.u[0] + du);
      if (p.parent != 0) {
        const Expr x = cb.flat(cb.mul(b.Dinv, du), "x");
        V6 t;
        for (int r = 0; r < 6; ++r) t[std::size_t(r)] = dp[std::size_t(r)] + cb.mul(b.U[0][std::size_t(r)], x);
        const V6 f = forceToParent(i, t);
        BodySym& par = bs(p.parent);
        for (int r = 0; r < 6; ++r)
          if (!f[std::size_t(r)].isZero())
            par.dp[std::size_t(r)] = putQ(kDP, p.parent, 6, r, par.dp[std::size_t(r)] + f[std::size_t(r)]);
      }
    }
    cb.close();
  }
}

void Emitter::copyOut() {
  endPart();
  CodeBuilder& cb = *cb_;
  for (int j = 0; j < plan_.nv; ++j)
    cb.line(fmt::format("qdd[{}] = {};", j, cb.print(st_.qdd[std::size_t(j)])), {st_.qdd[std::size_t(j)]});
  for (int r = 0; r < plan_.nc; ++r)
    cb.line(fmt::format("lambda[{}] = {};", r, cb.print(st_.lambda[std::size_t(r)])), {st_.lambda[std::size_t(r)]});
}

// The off-support accelerations, printed once (from constrainedABA's state)
// and called by both algorithms; their qdd come back into the caller's state.
void Emitter::callAccelerateFree() {
  endPart();
  if (accelerateText_.empty()) {
    supportAccelerations_ = accelerations(plan_.support);
    const Host saved = host_;
    const State savedState = st_;
    CodeBuilder* savedCb = cb_;
    accelerateText_ = emitAccelerateFree();
    afterAccel_ = st_;
    accelBuilder_ = cb_;
    host_ = saved;
    st_ = savedState;
    cb_ = savedCb;
  } else if (accelerations(plan_.support) != supportAccelerations_) {
    // accelerate_free_bodies reads the support accelerations as members: they
    // must be the same members in both algorithms.
    throw std::logic_error("emitter: the support accelerations differ between the two algorithms");
  }
  cb_->line("accelerate_free_bodies(w);");
  std::vector<int> cache;
  for (int i : plan_.offSupport)
    for (int d = 0; d < bp(i).nv; ++d) {
      const std::size_t j = std::size_t(bp(i).idx_v + d);
      st_.qdd[j] = cb_->import(*accelBuilder_, afterAccel_.qdd[j], cache);
    }
}

std::string Emitter::emitCaba() {
  beginHost("caba");
  hostMu_ = cb_->define("mu", "s.mu * Scalar(s.iterations > 0)", {});
  cb_->line("kinematics(q, v, w);");
  cb_->line("eliminate_free_bodies(tau, w);");
  for (auto it = plan_.support.rbegin(); it != plan_.support.rend(); ++it) {
    boundary();
    openBody(*it, "eliminate (penalty at the constraints):");
    eliminate(*it, true);
    cb_->close();
  }
  for (int i : plan_.support) {
    boundary();
    openBody(i, "accelerate");
    accelerate(i, bs(i).u);
    cb_->close();
  }
  if (plan_.nc > 0) {
    updateMultipliers(true);
    endPart();
    const std::string before = fingerprint(plan_.support, true);
    cb_->open("for (int k = 2; k <= s.iterations; ++k) {",
              {"Iterations 2..K: reduced sweeps over the support (K = 0 or 1: no pass)."});
    reducedSweep();
    for (int i : plan_.support) {
      boundary();
      openBody(i, "accelerate");
      accelerate(i, bs(i).u);
      cb_->close();
    }
    updateMultipliers(false);
    endPart();
    if (fingerprint(plan_.support, true) != before)
      throw std::logic_error("emitter: the iteration loop does not carry its state consistently");
    cb_->close();
  }
  callAccelerateFree();
  copyOut();
  return endHost({"q", "v", "tau", "s", "w", "qdd", "lambda"});
}

// KA of the support bodies (and the world) starts from their own rows: KA = K^T.
void Emitter::initRows() {
  auto init = [&](int i) {
    BodySym& b = bs(i);
    const int m = bp(i).m();
    b.KA.assign(std::size_t(m), zero6());
    int col = 0;
    for (int k : bp(i).constraints) {
      const Constraint& c = sys_.constraints[std::size_t(k)];
      const Mat6 X = c.placement.motionMatrixInv();
      for (int j = 0; j < c.rows(); ++j, ++col) {
        b.KA[std::size_t(col)] = constant(Vec6(X.row(j).transpose()));
      }
    }
  };
  init(0);
  for (int i : plan_.support) init(i);
}

// G(t, u), rows in tree order: the sum of KSD_i KS_i over the support bodies
// whose subtree holds both rows (Z_i . Z_i at the free flyer).
Expr Emitter::delassus(int t, int u, bool withFreeFlyer) {
  CodeBuilder& cb = *cb_;
  Expr g;
  for (const auto& [i, jt] : rowsAt_[std::size_t(t)]) {
    const auto it = rowsAt_[std::size_t(u)].find(i);
    if (it == rowsAt_[std::size_t(u)].end()) continue;
    const int ju = it->second;
    BodySym& b = bs(i);
    if (bp(i).jointClass == JointClass::FreeFlyer) {
      if (!withFreeFlyer) continue;
      for (int d = 0; d < 6; ++d) g += cb.mul(b.Z[std::size_t(jt)][std::size_t(d)], b.Z[std::size_t(ju)][std::size_t(d)]);
    } else {
      g += cb.mul(b.KSD[std::size_t(jt)], b.KS[std::size_t(ju)][0]);
    }
  }
  return g;
}

// The free-flyer body when it carries constraint rows (floating base), else -1.
int Emitter::freeFlyerWithRows() const {
  for (int i : plan_.support)
    if (bp(i).jointClass == JointClass::FreeFlyer && bp(i).m() > 0) return i;
  return -1;
}

// G + I/mu = L L^T, one block (and part) per column, G's entries summed in place.
// With a floating base, G = B + Z^T Z where Z^T Z (rank 6) comes from the free
// flyer and B couples only rows that share a limb: L factors A = B + I/mu,
// whose zeros between limbs fold away, and woodburyFactor handles the rest.
void Emitter::delassusCholesky() {
  const int nc = plan_.nc;
  rowsAt_.assign(std::size_t(nc), {});
  std::vector<int> position(static_cast<std::size_t>(nc));
  for (int t = 0; t < nc; ++t) position[std::size_t(plan_.rootRows[std::size_t(t)])] = t;
  for (int i : plan_.support)
    for (int j = 0; j < bp(i).m(); ++j)
      rowsAt_[std::size_t(position[std::size_t(bp(i).subtreeRows[std::size_t(j)])])][i] = j;
  st_.L = Sym(nc);
  st_.Linv.assign(std::size_t(nc), Expr());
  for (int j = 0; j < nc; ++j) {
    boundary();
    CodeBuilder& cb = *cb_;
    cb.open("{", {fmt::format("G + I/mu = L L^T, column {} (Cholesky, unrolled for the fixed row count)", j)});
    const bool full = freeFlyerWithRows() < 0;
    Expr d = delassus(j, j, full);  // before inv_mu: see mulAdd in symbolic.cpp
    d += cb.input("inv_mu");
    for (int k = 0; k < j; ++k) d -= cb.mul(st_.L(j, k), st_.L(j, k));
    const Expr r = cb.sqrt(d, "r");
    st_.Linv[std::size_t(j)] = put(member("Linv", nc, j, "1 / diag(L)"), cb.recip(r, "inv"));
    for (int i = j + 1; i < nc; ++i) {
      Expr e = delassus(i, j, full);
      for (int k = 0; k < j; ++k) e -= cb.mul(st_.L(i, k), st_.L(j, k));
      st_.L(i, j) = put(member("L", nc * (nc + 1) / 2, Sym::index(nc, i, j), "Cholesky factor of G + I/mu (lower, packed)"),
                        cb.mul(cb.flat(e), st_.Linv[std::size_t(j)]));
    }
    cb.close();
  }
}

// (A + Z^T Z)^-1 = L^-T (I - W S^-1 W^T) L^-1 with W = L^-1 Z^T, S = I + W^T W
// (Woodbury): six forward solves and a 6 x 6 factor instead of a dense one.
void Emitter::woodburyFactor(int ff) {
  const int nc = plan_.nc;
  std::vector<int> position(static_cast<std::size_t>(nc));
  for (int t = 0; t < nc; ++t) position[std::size_t(plan_.rootRows[std::size_t(t)])] = t;
  std::vector<int> column(static_cast<std::size_t>(nc), -1);  // tree row -> the free flyer's column
  for (int j = 0; j < bp(ff).m(); ++j) column[std::size_t(position[std::size_t(bp(ff).subtreeRows[std::size_t(j)])])] = j;
  st_.W.assign(std::size_t(nc), zero6());
  for (int d = 0; d < 6; ++d) {
    boundary();
    cb_->open("{", {fmt::format("W = L^-1 Z^T, column {}", d)});
    std::vector<Expr> z(static_cast<std::size_t>(nc));
    for (int t = 0; t < nc; ++t)
      if (column[std::size_t(t)] >= 0) z[std::size_t(t)] = bs(ff).Z[std::size_t(column[std::size_t(t)])][std::size_t(d)];
    const std::vector<Expr> w = forwardSolve(st_.L, st_.Linv, z);
    for (int t = 0; t < nc; ++t)
      st_.W[std::size_t(t)][std::size_t(d)] = put(member("W", 6 * nc, 6 * t + d, "L^-1 Z^T (row-major)"), w[std::size_t(t)]);
    cb_->close();
  }
  boundary();
  CodeBuilder& cb = *cb_;
  cb.open("{", {"S = I + W^T W = LS LS^T"});
  Sym S(6);
  for (int a = 0; a < 6; ++a)
    for (int b = a; b < 6; ++b) {
      Expr e = a == b ? Expr(1.0) : Expr();
      for (int t = 0; t < nc; ++t) e += cb.mul(st_.W[std::size_t(t)][std::size_t(a)], st_.W[std::size_t(t)][std::size_t(b)]);
      S(a, b) = e;
    }
  const Chol ch = cholesky(
      S, Expr(), [&](int r, int c) { return member("LS", 21, Sym::index(6, r, c), "factor of I + W^T W (lower, packed)"); },
      [&](int r) { return member("LSinv", 6, r, "1 / diag(LS)"); });
  st_.LS = ch.L;
  st_.LSinv = ch.inv;
  cb.close();
}

// (G + I/mu)^-1 rhs through the factors (rows in tree order).
std::vector<Expr> Emitter::delassusSolve(const std::vector<Expr>& rhs) {
  CodeBuilder& cb = *cb_;
  std::vector<Expr> z = forwardSolve(st_.L, st_.Linv, rhs);
  if (!st_.W.empty()) {
    std::vector<Expr> v(6);
    for (int d = 0; d < 6; ++d)
      for (std::size_t t = 0; t < z.size(); ++t) v[std::size_t(d)] += cb.mul(st_.W[t][std::size_t(d)], z[t]);
    const std::vector<Expr> x = backwardSolve(st_.LS, st_.LSinv, forwardSolve(st_.LS, st_.LSinv, v));
    for (std::size_t t = 0; t < z.size(); ++t) {
      for (int d = 0; d < 6; ++d) z[t] -= cb.mul(st_.W[t][std::size_t(d)], x[std::size_t(d)]);
      z[t] = cb.flat(z[t], "z");
    }
  }
  return backwardSolve(st_.L, st_.Linv, z);
}

std::string Emitter::emitPv() {
  beginHost("pv");
  const int nc = plan_.nc;
  cb_->line("kinematics(q, v, w);");
  cb_->line("eliminate_free_bodies(tau, w);");
  initRows();
  for (auto it = plan_.support.rbegin(); it != plan_.support.rend(); ++it) {
    boundary();
    openBody(*it, "eliminate, carrying the subtree rows:");
    eliminate(*it, false);
    pvRows(*it);
    cb_->close();
  }
  if (nc > 0) freeRowAccelerations();
  if (nc > 0) {
    endPart();
    hostInvMu_ = cb_->define("inv_mu", cb_->literal(1.0) + " / s.mu", {});
    delassusCholesky();
    if (freeFlyerWithRows() >= 0) woodburyFactor(freeFlyerWithRows());
    boundary();
    const std::vector<int>& rows = plan_.rootRows;
    for (int t = 0; t < nc; ++t)
      st_.lambda[std::size_t(rows[std::size_t(t)])] =
          cb_->store(member("lambda", nc, rows[std::size_t(t)], "multipliers (layout order)"), Expr());
    endPart();
    const std::string before = fingerprint({}, false);
    cb_->open("for (int k = 0; k < s.iterations; ++k) {",
              {"K proximal steps: (G + I/mu) lambda+ = y_free + lambda / mu (rows in tree order, stored in layout order)"});
    boundary();
    std::vector<Expr> rhs(static_cast<std::size_t>(nc));
    for (int t = 0; t < nc; ++t)
      rhs[std::size_t(t)] = st_.yfree[std::size_t(t)] + cb_->mul(cb_->input("inv_mu"), st_.lambda[std::size_t(rows[std::size_t(t)])]);
    const std::vector<Expr> x = delassusSolve(rhs);
    for (int t = 0; t < nc; ++t)
      st_.lambda[std::size_t(rows[std::size_t(t)])] =
          cb_->store(member("lambda", nc, rows[std::size_t(t)], "multipliers (layout order)"), x[std::size_t(t)]);
    endPart();
    if (fingerprint({}, false) != before)
      throw std::logic_error("emitter: the proximal loop does not carry its state consistently");
    cb_->close();
  }
  for (int i : plan_.support) {
    boundary();
    openBody(i, "accelerate, with the multipliers of the subtree rows:");
    BodySym& b = bs(i);
    std::vector<Expr> uEff = b.u;
    for (int j = 0; j < bp(i).m(); ++j) {
      const Expr& lam = st_.lambda[std::size_t(bp(i).subtreeRows[std::size_t(j)])];
      for (std::size_t d = 0; d < uEff.size(); ++d) uEff[d] -= cb_->mul(b.KS[std::size_t(j)][d], lam);
    }
    accelerate(i, uEff);
    cb_->close();
  }
  callAccelerateFree();
  copyOut();
  return endHost({"q", "v", "tau", "s", "w", "qdd", "lambda"});
}

std::string scalarName(ScalarType t) { return t == ScalarType::Float ? "float" : "double"; }

SolverFiles Emitter::run(const SolverInputs& in, SolverStats* stats) {
  const int N = m_.numBodies();
  st_.b.resize(std::size_t(N));
  st_.k.resize(sys_.constraints.size());
  st_.qdd.assign(std::size_t(plan_.nv), Expr());
  st_.lambda.assign(std::size_t(plan_.nc), Expr());
  st_.dlambda.assign(std::size_t(plan_.nc), Expr());
  st_.yfree.assign(std::size_t(plan_.nc), Expr());

  const std::string kinText = emitKinematics();
  const std::string elimText = emitEliminateFree();
  const State afterElim = st_;
  CodeBuilder* elimBuilder = cb_;
  const std::string cabaText = emitCaba();
  st_ = afterElim;
  cb_ = elimBuilder;
  const std::string pvText = emitPv();
  cb_ = nullptr;

  // The workspace, grouped as the members were first written.
  std::string members;
  int scalars = 0;
  for (const Member& mb : members_) {
    const std::string decl = mb.size == 0 ? fmt::format("Scalar {};", mb.name) : fmt::format("Scalar {}[{}];", mb.name, mb.size);
    members += fmt::format("  {:<28} // {}\n", decl, mb.comment);
    scalars += mb.size == 0 ? 1 : mb.size;
  }
  const int scalarBytes = plan_.scalar == ScalarType::Float ? 4 : 8;

  std::string joints;
  for (int i = 1; i < N; ++i) {
    const BodyPlan& b = bp(i);
    joints += fmt::format("//   q[{}..{}] v[{}..{}]  joint '{}' ({}), link '{}'\n", b.idx_q, b.idx_q + b.nq - 1, b.idx_v,
                          b.idx_v + b.nv - 1, escapeComment(b.joint), jointClassName(b.jointClass), escapeComment(b.link));
  }
  std::string constraints;
  for (const ConstraintPlan& c : plan_.constraints)
    constraints += fmt::format("//   lambda[{}..{}]  '{}' ({}) on link '{}'\n", c.row, c.row + c.rows - 1, escapeComment(c.name),
                               c.weld ? "6d weld" : "3d point contact", escapeComment(c.link));
  if (constraints.empty()) constraints = "//   (none)\n";

  const std::string banner = fmt::format(
      fmt::runtime(kBannerTemplate), fmt::arg("version", PROXGEN_VERSION), fmt::arg("urdf", escapeComment(in.urdfName)),
      fmt::arg("layout", escapeComment(in.layoutName)), fmt::arg("command", escapeComment(in.command)),
      fmt::arg("robot", escapeComment(m_.name)),
      fmt::arg("urdf_sha", in.urdfSha256), fmt::arg("layout_sha", in.layoutSha256));

  SolverFiles files;
  files.headerName = plan_.name + ".hpp";
  files.sourceName = plan_.name + ".cpp";
  CodeBuilder lit(plan_.scalar);
  files.header = fmt::format(
      fmt::runtime(kHeaderTemplate), fmt::arg("banner", banner),
      fmt::arg("q_convention", plan_.floatingBase ? "x y z qx qy qz qw of the base, then one value per joint"
                                                  : "one value per joint"),
      fmt::arg("joint_table", joints), fmt::arg("constraint_table", constraints), fmt::arg("name", plan_.name),
      fmt::arg("scalar", scalarName(plan_.scalar)), fmt::arg("nq", plan_.nq), fmt::arg("nv", plan_.nv),
      fmt::arg("nc", plan_.nc), fmt::arg("mu", lit.literal(plan_.mu)), fmt::arg("iterations", plan_.iterations),
      fmt::arg("workspace_bytes", scalars * scalarBytes), fmt::arg("members", members));
  files.source = fmt::format(fmt::runtime(kSourceTemplate), fmt::arg("banner", banner), fmt::arg("name", plan_.name),
                             fmt::arg("parts", partsText_), fmt::arg("kinematics", kinText), fmt::arg("eliminate_free", elimText),
                             fmt::arg("accelerate_free", accelerateText_), fmt::arg("caba", cabaText),
                             fmt::arg("pv", pvText));
  if (stats) {
    stats->statements = stats_.statements;
    stats->temporaries = stats_.temporaries;
    stats->multiplies = stats_.multiplies;
    stats->workspaceScalars = scalars;
  }
  return files;
}

}  // namespace

SolverFiles emitSolver(const System& sys, const Plan& plan, const SolverInputs& inputs, SolverStats* stats) {
  Emitter e(sys, plan);
  return e.run(inputs, stats);
}

}  // namespace proxgen::emit
