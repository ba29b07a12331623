#include "emit/body_state.hpp"

#include <algorithm>

namespace proxgen::emit {

void forEachExpr(Live& s, const std::function<void(Expr&)>& f) {
  auto v3 = [&](V3& x) { for (Expr& e : x) f(e); };
  auto v6 = [&](V6& x) { for (Expr& e : x) f(e); };
  auto sym = [&](Sym& m) { for (int k = 0; k < m.packedSize(); ++k) f(m.packed(k)); };
  auto vec = [&](std::vector<Expr>& x) { for (Expr& e : x) f(e); };
  auto xs = [&](XSym& X) {
    for (Expr& e : X.R) f(e);
    v3(X.p);
  };
  std::size_t n = 0;
  if (s.kin) n = s.kin->b.size();
  if (s.art) n = std::max(n, s.art->b.size());
  if (s.motion) n = std::max(n, s.motion->a.size());
  if (s.rows) n = std::max(n, s.rows->b.size());
  if (s.forces) n = std::max(n, s.forces->a.size());
  if (s.js) n = std::max({n, s.js->Ic.size(), s.js->FA.size()});
  for (std::size_t i = 0; i < n; ++i) {
    Kinematics::Body* kb = s.kin && i < s.kin->b.size() ? &s.kin->b[i] : nullptr;
    Articulated::Body* ab = s.art && i < s.art->b.size() ? &s.art->b[i] : nullptr;
    ProxRows::Body* rb = s.rows && i < s.rows->b.size() ? &s.rows->b[i] : nullptr;
    if (kb) xs(kb->XJ), xs(kb->oM), v6(kb->v), v6(kb->c);
    if (s.motion && i < s.motion->a.size()) v6(s.motion->a[i]);
    if (kb) v6(kb->pA);
    if (ab) v6(ab->pA);
    if (s.inc && i < s.inc->dp.size()) v6(s.inc->dp[i]);
    if (kb) v3(kb->g);
    if (ab) sym(ab->IA), sym(ab->L);
    if (rb) {
      vec(rb->KSD);
      for (V6& x : rb->Z) v6(x);
    }
    if (ab)
      for (V6& x : ab->U) v6(x);
    if (rb) {
      for (V6& x : rb->KA) v6(x);
      for (auto& x : rb->KS) vec(x);
    }
    if (ab) f(ab->Dinv), vec(ab->Linv), vec(ab->u);
    if (s.forces && i < s.forces->a.size()) v6(s.forces->a[i]), v6(s.forces->f[i]);
    if (s.js && i < s.js->Ic.size()) f(s.js->Ic[i].m), v3(s.js->Ic[i].h), sym(s.js->Ic[i].I);
    if (s.js && i < s.js->FA.size())
      for (V6& x : s.js->FA[i]) v6(x);
  }
  if (s.kin)
    for (auto& x : s.kin->k) vec(x);
  if (s.motion) vec(s.motion->qdd);
  if (s.mult) vec(s.mult->lambda), vec(s.mult->dlambda);
  if (s.rows) vec(s.rows->yfree);
  if (s.forces) vec(s.forces->tau);
  if (s.js) {
    for (V6& x : s.js->carried) v6(x);
    sym(s.js->upper);
  }
  if (s.del) {
    vec(s.del->Linv), vec(s.del->LSinv);
    sym(s.del->L), sym(s.del->LS);
    for (V6& x : s.del->W) v6(x);
    vec(s.del->lowRank);
  }
  if (s.cons) {
    for (Sym& m : s.cons->Phi) sym(m);
    for (auto& x : s.cons->T) vec(x);
    vec(s.cons->out);
  }
}

}  // namespace proxgen::emit
