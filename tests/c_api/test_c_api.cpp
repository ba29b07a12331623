// The C door (issue 18 item 5; docs/design.md "The C interface"): every
// function of quadruped_c.h, called from C (c_calls.c, compiled by the C
// compiler as C99 with -Werror -pedantic) in a caller-provided buffer of
// quadruped_work_size() bytes, gives the bits of the C++ API called with the
// same arguments: the wrapper is the same code behind a different door, so
// anything but equality is an argument passed wrongly (swapped arrays, a
// dropped mu, iterations, lambda0 or active flag). The inputs are distinct
// non-trivial values per argument, mu and iterations are not the defaults, so
// a swap or a default shows. Also the README's two controller loops (C in
// c_calls.c, C++ here, between README markers) run the same schedule and
// agree bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "c_calls.h"
#include "quadruped.hpp"

namespace {

namespace qp = quadruped;

// A state with every slot distinct (a non-unit quaternion: normalised inside).
struct Inputs {
  double q[qp::nq], v[qp::nv], tau[qp::nv], qdd[qp::nv], lambda[qp::nc], lambda0[qp::nc];
  Inputs() {
    for (int k = 0; k < qp::nq; ++k) q[k] = 0.1 + 0.03 * k;
    for (int k = 0; k < qp::nv; ++k) {
      v[k] = 0.2 - 0.05 * k;
      tau[k] = std::sin(1.0 + k);
      qdd[k] = 0.3 * std::cos(2.0 + k);
    }
    for (int k = 0; k < qp::nc; ++k) {
      lambda[k] = 5.0 - 1.5 * k;
      lambda0[k] = -3.0 + 0.7 * k;
    }
  }
};

template <int N>
std::vector<double> vec(const double (&x)[N]) {
  return std::vector<double>(x, x + N);
}
std::vector<double> vec(const double* x, int n) { return std::vector<double>(x, x + n); }

TEST(CApi, WorkSizeAndAlignmentAreTheWorkspaces) {
  EXPECT_EQ(c_work_size(), sizeof(qp::Workspace));
  EXPECT_EQ(std::size_t(quadruped_WORK_SIZE), sizeof(qp::Workspace));
  EXPECT_EQ(c_work_align() % alignof(qp::Workspace), 0u);
  EXPECT_EQ(quadruped_NQ, qp::nq);
  EXPECT_EQ(quadruped_NV, qp::nv);
  EXPECT_EQ(quadruped_NC, qp::nc);
  EXPECT_EQ(quadruped_NCONS, qp::ncons);
  EXPECT_EQ(quadruped_CONSTRAINT_rh_foot, qp::constraint::rh_foot);
  EXPECT_EQ(quadruped_ROW_rh_foot, qp::constraint_row[qp::constraint::rh_foot]);
}

TEST(CApi, EveryFunctionGivesTheBitsOfTheCxxApi) {
  const Inputs in;
  const double mu = 321.5;  // neither the layout's mu nor its iterations
  const int iterations = 5;
  const unsigned char all[qp::ncons] = {1, 1, 1, 1}, mixed[qp::ncons] = {1, 0, 1, 1};
  // NULL and all-ones must both be the default (all in force); the mixed flags
  // are compared C against C++ with the same Settings::active, whatever their meaning.
  const unsigned char* actives[] = {nullptr, all, mixed};
  for (const unsigned char* active : actives)
    for (const double* lambda0 : {static_cast<const double*>(nullptr), in.lambda0}) {
      SCOPED_TRACE(std::string("active ") + (active == nullptr ? "NULL" : active == all ? "all" : "mixed") +
                   ", lambda0 " + (lambda0 ? "set" : "NULL"));
      static c_results c;
      std::memset(&c, 0xff, sizeof c);  // NaN everywhere: an output the wrapper does not write shows
      c_call_all(in.q, in.v, in.tau, in.qdd, in.lambda, mu, iterations, active, lambda0, &c);

      static qp::Workspace w;
      qp::Settings s;
      s.mu = mu;
      s.iterations = iterations;
      s.lambda0 = lambda0;
      if (active)
        for (int k = 0; k < qp::ncons; ++k) s.active[k] = active[k] != 0;
      double qdd[qp::nv], lambda[qp::nc];
      qp::constrained_aba(in.q, in.v, in.tau, s, w, qdd, lambda);
      EXPECT_EQ(vec(c.caba_qdd), vec(qdd));
      EXPECT_EQ(vec(c.caba_lambda), vec(lambda));
      EXPECT_EQ(c.caba_residual, qp::residual(w));
      qp::prox_pv(in.q, in.v, in.tau, s, w, qdd, lambda);
      EXPECT_EQ(vec(c.pv_qdd), vec(qdd));
      EXPECT_EQ(vec(c.pv_lambda), vec(lambda));
      EXPECT_EQ(c.pv_residual, qp::residual(w));

      static double out[qp::nv * qp::nv];
      qp::inverse_dynamics(in.q, in.v, in.qdd, in.lambda, w, out, s.active);
      EXPECT_EQ(vec(c.tau), vec(out, qp::nv));
      qp::nonlinear_effects(in.q, in.v, w, out);
      EXPECT_EQ(vec(c.h), vec(out, qp::nv));
      qp::mass_matrix(in.q, w, out);
      EXPECT_EQ(vec(c.M), vec(out, qp::nv * qp::nv));
      qp::mass_matrix_inverse(in.q, w, out);
      EXPECT_EQ(vec(c.Minv), vec(out, qp::nv * qp::nv));
      qp::constraint_placements(in.q, w, out);
      EXPECT_EQ(vec(c.X), vec(out, 12 * qp::ncons));
      qp::constraint_jacobian(in.q, w, out, s.active);
      EXPECT_EQ(vec(c.J), vec(out, qp::nc * qp::nv));
      qp::constraint_drift(in.q, in.v, w, out, s.active);
      EXPECT_EQ(vec(c.gamma), vec(out, qp::nc));
      qp::delassus(in.q, w, out, s.active);
      EXPECT_EQ(vec(c.G), vec(out, qp::nc * qp::nc));
      qp::Settings sd;  // delassus_inverse reads mu (and the flags)
      sd.mu = mu;
      if (active)
        for (int k = 0; k < qp::ncons; ++k) sd.active[k] = active[k] != 0;
      qp::delassus_inverse(in.q, sd, w, out);
      EXPECT_EQ(vec(c.Ginv), vec(out, qp::nc * qp::nc));
      qp::constraint_wrenches(in.q, in.lambda, w, out);
      EXPECT_EQ(vec(c.W), vec(out, 6 * qp::ncons));
    }
}

// NULL flags and all-ones flags are the same call, and lambda0 moves the
// answer (so the comparisons above could see a dropped lambda0).
TEST(CApi, NullFlagsAreAllInForceAndLambda0IsRead) {
  const Inputs in;
  const unsigned char all[qp::ncons] = {1, 1, 1, 1};
  static c_results a, b, c;
  c_call_all(in.q, in.v, in.tau, in.qdd, in.lambda, 1e4, 3, nullptr, nullptr, &a);
  c_call_all(in.q, in.v, in.tau, in.qdd, in.lambda, 1e4, 3, all, nullptr, &b);
  c_call_all(in.q, in.v, in.tau, in.qdd, in.lambda, 1e4, 3, all, in.lambda0, &c);
  EXPECT_EQ(vec(a.pv_lambda), vec(b.pv_lambda));
  EXPECT_EQ(vec(a.caba_qdd), vec(b.caba_qdd));
  EXPECT_NE(vec(a.pv_lambda), vec(c.pv_lambda));
}

// ---- The README's C++ controller loop, as printed there (between the markers).
// README-CPP-BEGIN
namespace qp = quadruped;

qp::Workspace w;                  // once, e.g. static: caller-owned, ~95 kB with every function
qp::Scalar lambda[qp::nc] = {};   // kept between steps: the next step's warm start
qp::Settings s;

// One step: W gets each foot's wrench on the robot (world axes).
void step(const qp::Scalar* q, const qp::Scalar* v, const qp::Scalar* tau, bool lfInSwing, qp::Scalar* qdd,
          qp::Scalar W[6 * qp::ncons]) {
  s.active[qp::constraint::lf_foot] = !lfInSwing;  // contact schedule
  s.lambda0 = lambda;                              // warm start (read before lambda is written)
  s.iterations = 2;
  qp::prox_pv(q, v, tau, s, w, qdd, lambda);
  if (qp::residual(w) > 1e-6) {  // not accurate enough yet: 8 more updates from here
    s.iterations = 8;
    qp::prox_pv(q, v, tau, s, w, qdd, lambda);
  }
  qp::constraint_wrenches(q, lambda, w, W);  // W + 6 k: force, torque of foot k about its contact point
}
// README-CPP-END

TEST(CApi, TheReadmeControllerLoopsAgree) {
  const Inputs in;
  ASSERT_EQ(double(s.mu), 1e4);  // the C loop passes 1e4: the layout's mu
  double qddC[qp::nv], lambdaC[qp::nc], residualC = 0, WC[6 * qp::ncons];
  c_controller(in.q, in.v, in.tau, 6, qddC, lambdaC, &residualC, WC);
  double qdd[qp::nv], W[6 * qp::ncons];
  for (int k = 0; k < 6; ++k) step(in.q, in.v, in.tau, k % 2 == 1, qdd, W);
  EXPECT_EQ(vec(qddC), vec(qdd));
  EXPECT_EQ(vec(lambdaC), vec(lambda));
  EXPECT_EQ(residualC, double(qp::residual(w)));
  EXPECT_EQ(vec(WC), vec(W));
  double largest = 0;
  for (double x : W) largest = std::max(largest, std::abs(x));
  EXPECT_GT(largest, 0.0);  // the loops computed forces (a comparison of zeros could hide a dead loop)
}

// The README shows both loops as they are compiled here: the text between the
// markers of this file and of c_calls.c appears in README.md verbatim.
std::string between(const std::string& path, const std::string& begin, const std::string& end) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const std::size_t a = text.find(begin), b = text.find(end);
  if (a == std::string::npos || b == std::string::npos) return "<markers missing in " + path + ">";
  return text.substr(a + begin.size(), b - a - begin.size());
}

TEST(CApi, TheReadmeShowsTheCompiledLoops) {
  const std::string src = PROXGEN_TEST_SOURCE_DIR;
  std::ifstream in(src + "/README.md");
  std::stringstream readme;
  readme << in.rdbuf();
  const std::string cpp = between(src + "/tests/c_api/test_c_api.cpp", "// README-CPP-BEGIN\n", "// README-CPP-END");
  const std::string c = between(src + "/tests/c_api/c_calls.c", "/* README-C-BEGIN */\n", "/* README-C-END */");
  EXPECT_NE(readme.str().find("```cpp\n#include \"quadruped.hpp\"\n" + cpp + "```"), std::string::npos) << cpp;
  EXPECT_NE(readme.str().find("```c\n" + c + "```"), std::string::npos) << c;
}

}  // namespace
