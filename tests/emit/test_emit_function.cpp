// The part-function writer (emit/function.hpp): a part's parameters come from
// what its live statements read and write (the expression graph), parts are
// named by host, pass and body range, a pass's banner is printed once above
// its first call, and a part whose statements all folded away prints nothing.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <string>

#include "emit/function.hpp"

namespace proxgen::emit {
namespace {

TEST(AccessedNames, LiveStatementsOnly) {
  CodeBuilder cb(ScalarType::Double);
  const Expr q = cb.input("q[0]"), v = cb.input("v[1]");
  cb.temp(cb.mul(v, v), "dead");  // never stored: not printed, not accessed
  cb.store("w.x", 2.0 * q);
  cb.line("f(s);", {}, {"s"});
  const std::set<std::string> names = cb.accessedNames();
  EXPECT_EQ(names, (std::set<std::string>{"q[0]", "w.x", "s"}));
}

// Writes one host with two passes; returns the host body and the parts.
struct Written {
  std::string host, parts;
};

Written write(bool foldSecond) {
  FunctionWriter fn(ScalarType::Double, {"world", "hip", "knee"}, {"", "h", "k"});
  fn.beginHost("caba", nullptr);
  fn.beginPass("backward", "backward: the elimination");
  for (int i : {2, 1}) {
    fn.boundary(i);
    fn.cb().open("{");
    fn.cb().store("w.u_" + std::to_string(i), fn.cb().input("tau[" + std::to_string(i - 1) + "]"));
    fn.cb().close();
  }
  fn.beginPass("forward", "forward: accelerations");
  fn.boundary(1);
  fn.cb().open("{");
  // A temporary nobody stores is not printed: the part is empty when folded.
  if (foldSecond) fn.cb().temp(fn.cb().mul(fn.cb().member("w.u_1"), fn.cb().member("w.u_2")));
  else fn.cb().store("w.a_1", fn.cb().mul(fn.cb().member("w.u_1"), fn.cb().member("w.u_2")));
  fn.cb().close();
  Written out;
  out.host = fn.endHost({"tau", "w", "q"});
  out.parts = fn.parts();
  return out;
}

TEST(FunctionWriter, NamesParametersAndBanners) {
  const Written w = write(false);
  // One part per pass here (both are under the statement budget), named by
  // host, pass and its first and last body.
  EXPECT_NE(w.parts.find("void caba_backward_knee_to_hip(const Scalar* PROXGEN_RT_RESTRICT tau, "
                         "Workspace& PROXGEN_RT_RESTRICT w) noexcept {"),
            std::string::npos)
      << w.parts;
  // The forward part reads only members: no tau.
  EXPECT_NE(w.parts.find("void caba_forward_hip(Workspace& PROXGEN_RT_RESTRICT w) noexcept {"), std::string::npos)
      << w.parts;
  EXPECT_EQ(w.host,
            "  static_cast<void>(q);\n"
            "  // ---- backward: the elimination\n"
            "  caba_backward_knee_to_hip(tau, w);\n"
            "  // ---- forward: accelerations\n"
            "  caba_forward_hip(w);\n");
}

TEST(FunctionWriter, AFoldedPartPrintsNoFunctionNoCallNoBanner) {
  const Written w = write(true);
  EXPECT_EQ(w.parts.find("caba_forward"), std::string::npos) << w.parts;
  EXPECT_EQ(w.host.find("forward"), std::string::npos) << w.host;
}

// Parts close when full, but a body right after its twin (the same shape: a
// left and a right leg's link) stays in the part of its twin, so that their
// blocks can run as a pair; a third body of that shape starts its own.
TEST(FunctionWriter, TwinsShareAPart) {
  FunctionWriter fn(ScalarType::Double, {"world", "l", "r", "m", "o"}, {"", "leg", "leg", "leg", "arm"});
  fn.beginHost("kin", nullptr);
  fn.beginPass("", "");
  for (int i : {1, 2, 3, 4}) {
    fn.boundary(i);
    fn.cb().open("{");
    for (int k = 0; k < FunctionWriter::kPartBudget; ++k)  // a full part per block
      fn.cb().store(fmt::format("w.x_{}[{}]", i, k), fn.cb().input(fmt::format("q[{}]", k)));
    fn.cb().close();
  }
  const std::string host = fn.endHost({"q", "w"});
  EXPECT_EQ(host,
            "  kin_l_to_r(q, w);\n"
            "  kin_m(q, w);\n"
            "  kin_o(q, w);\n");
}

}  // namespace
}  // namespace proxgen::emit
