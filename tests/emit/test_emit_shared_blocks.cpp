// Shared blocks (emit/shared_blocks.hpp): body blocks that are the same code up
// to their constants, members and input offsets become one kernel called with
// each block's table; anything else stays as printed. That the shared code
// computes what the blocks did is the generated suites' job (tests/generated:
// every solver against its generic twin, Solo, Talos and the Atlas with shared
// blocks); this checks the rewriting itself and which solvers share.
#include <gtest/gtest.h>
#include <fmt/format.h>

#include <string>

#include "cases/cases.hpp"
#include "emit/shared_blocks.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// A part with one block for body `b` (dof `d`): the same statements for every
// body, `c` its constant, `sign` the sign the printer put before it.
std::string part(const std::string& name, const std::string& b, int d, const std::string& c, char sign = '+') {
  return fmt::format(
      "PROXGEN_RT_NOINLINE void {0}(const Scalar* PROXGEN_RT_RESTRICT tau, Workspace& PROXGEN_RT_RESTRICT w) noexcept {{\n"
      "  // body {2} '{1}': joint '{1}_joint' (revolute about z), parent 'base'\n"
      "  {{\n"
      "    const Scalar t{2} = w.IA_{1}[3] {4} {3}*w.Dinv_{1};\n"
      "    w.u_{1}[0] = -w.pA_{1}[5] + tau[{2}];\n"
      "    w.IA_base[{2}] = w.IA_base[{2}] + t{2}*w.u_{1}[0] - 1.5e-05*tau[{5}];\n"
      "  }}\n"
      "}}\n\n",
      name, b, d, c, sign, d + 1);
}

Members members(const std::vector<std::string>& bodies) {
  Members ws;
  for (const std::string& b : bodies) {
    ws.member("IA_" + b, 21, 0, "articulated inertia");
    ws.member("Dinv_" + b, 0, 0, "1 / D");
    ws.member("u_" + b, 1, 0, "tau - S^T pA");
    ws.member("pA_" + b, 6, 0, "bias force");
  }
  ws.member("IA_base", 21, 0, "articulated inertia");
  return ws;
}

const auto all = [](const std::string&) { return true; };

TEST(SharedBlocks, BlocksEqualUpToConstantsMembersAndOffsetsShareOneKernel) {
  const std::string text = part("caba_left", "left", 2, "0.25") + part("caba_right", "right", 4, "0.5", '-');
  const SharedParts s = shareBlocks(text, members({"left", "right"}), all, false);
  ASSERT_EQ(s.kernels.size(), 1u);
  EXPECT_EQ(s.kernels[0].name, "shared_0");
  ASSERT_EQ(s.kernels[0].blocks.size(), 2u);
  // One kernel body over k[], each block's constants in its own table; the
  // sign before a literal goes into the table (a - 0.5*x == a + (-0.5)*x).
  // A constant the blocks have in common (1.5e-05) stays a literal.
  EXPECT_EQ(test::occurrences(s.parts, "PROXGEN_RT_NOINLINE void shared_0("), 1);
  EXPECT_NE(s.parts.find("constexpr Scalar shared_0_k0[1] = {0.25};"), std::string::npos) << s.parts;
  EXPECT_NE(s.parts.find("constexpr Scalar shared_0_k1[1] = {-0.5};"), std::string::npos) << s.parts;
  // A scalar member the block only reads comes by value, arrays as pointers.
  EXPECT_NE(s.parts.find("const Scalar x0 = IA_m0[0] + k[0]*Dinv_m1;"), std::string::npos) << s.parts;
  // Inputs and members rebased at their smallest index, so one text serves both.
  EXPECT_NE(s.parts.find("IA_m4[0] = IA_m4[0] + x0*u_m2[0] - 1.5e-05*tau[1];"), std::string::npos) << s.parts;
  EXPECT_NE(s.parts.find("  shared_0(shared_0_k0, &tau[2], &w.IA_left[3], w.Dinv_left, w.u_left, &w.pA_left[5], "
                         "&w.IA_base[2]);"),
            std::string::npos)
      << s.parts;
  EXPECT_NE(s.parts.find("  shared_0(shared_0_k1, &tau[4], &w.IA_right[3], w.Dinv_right, w.u_right, &w.pA_right[5], "
                         "&w.IA_base[4]);"),
            std::string::npos)
      << s.parts;
  // The blocks' statements are gone from the parts, their comment lines stay.
  EXPECT_EQ(test::occurrences(s.parts, "w.Dinv_"), 2);
  EXPECT_EQ(test::occurrences(s.parts, "// body 2 'left'"), 1);
}

TEST(SharedBlocks, BlocksWithTheSameConstantsNeedNoTable) {
  const std::string text = part("a", "left", 2, "0.25") + part("b", "right", 4, "0.25", '-');
  const SharedParts s = shareBlocks(text, members({"left", "right"}), all, false);
  ASSERT_EQ(s.kernels.size(), 1u);
  EXPECT_EQ(test::occurrences(s.parts, "constexpr Scalar shared_0_k"), 2);  // 0.25 and -0.25 differ: a table each
  EXPECT_NE(s.parts.find("- 1.5e-05*tau[1];"), std::string::npos) << s.parts;
  const std::string same = part("a", "left", 2, "0.25") + part("b", "right", 4, "0.25");
  const SharedParts t = shareBlocks(same, members({"left", "right"}), all, false);
  ASSERT_EQ(t.kernels.size(), 1u);
  EXPECT_EQ(test::occurrences(t.parts, "constexpr Scalar"), 0);
  EXPECT_NE(t.parts.find("const Scalar x0 = IA_m0[0] + 0.25*Dinv_m1;"), std::string::npos) << t.parts;
  EXPECT_NE(t.parts.find("  shared_0(&tau[2], &w.IA_left[3], w.Dinv_left"), std::string::npos) << t.parts;
}

TEST(SharedBlocks, OtherCodeAndIneligiblePartsStayAsPrinted) {
  // A third body whose block multiplies where the others add: no kernel of its own.
  std::string odd = part("caba_odd", "odd", 6, "0.5");
  odd.replace(odd.find("t6*w.u_odd[0]"), 13, "t6/w.u_odd[0]");
  const std::string text = part("caba_left", "left", 2, "0.25") + part("caba_right", "right", 4, "0.5") + odd;
  const Members ws = members({"left", "right", "odd"});
  const SharedParts s = shareBlocks(text, ws, all, false);
  ASSERT_EQ(s.kernels.size(), 1u);
  EXPECT_EQ(s.kernels[0].blocks.size(), 2u);
  EXPECT_NE(s.parts.find("t6/w.u_odd[0]"), std::string::npos);
  // Nothing eligible, or nothing to share: the text comes back byte for byte.
  const SharedParts none = shareBlocks(text, ws, [](const std::string&) { return false; }, false);
  EXPECT_TRUE(none.kernels.empty());
  EXPECT_EQ(none.parts, text);
  EXPECT_EQ(shareBlocks(odd, ws, all, false).parts, odd);
  // Only the eligible part's block would be shared: one block is no group.
  const SharedParts one = shareBlocks(text, ws, [](const std::string& p) { return p == "caba_left"; }, false);
  EXPECT_EQ(one.parts, text);
}

TEST(SharedBlocks, ABlockReadingWhatAKernelCouldNotIsLeftAlone) {
  // t_part: a temporary of the part, outside the block (the kernel has no such parameter).
  auto reading = [](const std::string& name, const std::string& b, int d) {
    std::string p = part(name, b, d, "0.25");
    p.replace(p.find("-w.pA_"), 1, "t_part - ");
    return p;
  };
  const std::string text = reading("a", "left", 2) + reading("b", "right", 4);
  const SharedParts s = shareBlocks(text, members({"left", "right"}), all, false);
  EXPECT_TRUE(s.kernels.empty());
  EXPECT_EQ(s.parts, text);
}

// One part holding the blocks of `part` for bodies a and b, one after the
// other (a left and a right leg in the sweep's order).
std::string onePart(const std::string& a, int da, const std::string& b, int db) {
  const auto block = [](const std::string& p) {
    const std::size_t open = p.find('\n') + 1;
    return p.substr(open, p.rfind("}\n") - open);
  };
  const std::string first = part("caba", a, da, "0.25"), second = part("caba", b, db, "0.5", '-');
  return first.substr(0, first.find('\n') + 1) + block(first) + block(second) + "}\n\n";
}

TEST(SharedBlocks, TwoIndependentBlocksOneAfterTheOtherRunAsAPair) {
  const std::string text = onePart("left", 2, "right", 4);
  const SharedParts s = shareBlocks(text, members({"left", "right"}), all, true);
  ASSERT_EQ(s.kernels.size(), 1u);
  EXPECT_EQ(s.kernels[0].pairs, 1);
  // One call of the paired form, each lane's arguments side by side (a part's
  // scalar would come once); no single form is printed when no block needs it.
  EXPECT_NE(s.parts.find("  shared_0_x2(shared_0_p0, &tau[2], &tau[4], &w.IA_left[3], &w.IA_right[3], w.Dinv_left, "
                         "w.Dinv_right, w.u_left, w.u_right, &w.pA_left[5], &w.pA_right[5], &w.IA_base[2], "
                         "&w.IA_base[4]);"),
            std::string::npos)
      << s.parts;
  EXPECT_EQ(test::occurrences(s.parts, "void shared_0("), 0) << s.parts;
  EXPECT_EQ(test::occurrences(s.parts, "using ScalarPair = proxgen_rt::lanes<Scalar, 2>;"), 1);
  // Every constant in the table of pairs, common ones too ({a0, b0, a1, b1}),
  // aligned so that each pair is one load.
  EXPECT_NE(s.parts.find("alignas(2 * sizeof(Scalar)) constexpr Scalar shared_0_p0[4] = {0.25, -0.5, -1.5e-05, "
                         "-1.5e-05};"),
            std::string::npos)
      << s.parts;
  // The block's statements over pairs: what it reads gathered, what it stores
  // scattered, the member read by value gathered from the two values.
  EXPECT_NE(s.parts.find("  const ScalarPair x0 = proxgen_rt::gather2(IA_m0_a[0], IA_m0_b[0]) + "
                         "proxgen_rt::pair_at(k, 0)*proxgen_rt::gather2(Dinv_m1_a, Dinv_m1_b);"),
            std::string::npos)
      << s.parts;
  EXPECT_NE(s.parts.find("  proxgen_rt::scatter2<Scalar>(-proxgen_rt::gather2(pA_m3_a[0], pA_m3_b[0]) + "
                         "proxgen_rt::gather2(tau_a[0], tau_b[0]), u_m2_a[0], u_m2_b[0]);"),
            std::string::npos)
      << s.parts;
  // Both blocks' comment lines stay, their statements are gone.
  EXPECT_EQ(test::occurrences(s.parts, "// body 2 'left'"), 1);
  EXPECT_EQ(test::occurrences(s.parts, "// body 4 'right'"), 1);
  EXPECT_EQ(test::occurrences(s.parts, "w.Dinv_"), 2);
  // Without pairs: two calls of the single form.
  const SharedParts single = shareBlocks(text, members({"left", "right"}), all, false);
  EXPECT_EQ(single.kernels[0].pairs, 0);
  EXPECT_EQ(test::occurrences(single.parts, "_x2"), 0);
  EXPECT_EQ(test::occurrences(single.parts, "  shared_0(shared_0_k"), 2);
}

TEST(SharedBlocks, BlocksThatTouchWhatTheOtherStoresAreNoPair) {
  // Both store w.IA_base[2] (two children's terms added into their parent's).
  const std::string both = onePart("left", 2, "right", 2);
  const SharedParts s = shareBlocks(both, members({"left", "right"}), all, true);
  ASSERT_EQ(s.kernels.size(), 1u);
  EXPECT_EQ(s.kernels[0].pairs, 0);
  EXPECT_EQ(test::occurrences(s.parts, "_x2"), 0);
  EXPECT_EQ(test::occurrences(s.parts, "  shared_0(shared_0_k"), 2);
  // A call inside an expression would take a pair: the kernel keeps its single form.
  std::string sqrt = onePart("left", 2, "right", 4);
  for (std::size_t at = sqrt.find("w.Dinv_"); at != std::string::npos; at = sqrt.find("w.Dinv_", at + 12)) {
    const std::size_t end = sqrt.find(';', at);
    sqrt.insert(end, ")");
    sqrt.insert(at, "std::sqrt(");
  }
  const SharedParts withCall = shareBlocks(sqrt, members({"left", "right"}), all, true);
  ASSERT_EQ(withCall.kernels.size(), 1u) << withCall.parts;
  EXPECT_EQ(withCall.kernels[0].pairs, 0);
  EXPECT_EQ(test::occurrences(withCall.parts, "  shared_0(shared_0_k"), 2) << withCall.parts;
  // Not one after the other: two parts.
  const std::string apart = part("a", "left", 2, "0.25") + part("b", "right", 4, "0.5", '-');
  EXPECT_EQ(shareBlocks(apart, members({"left", "right"}), all, true).kernels[0].pairs, 0);
}

// A left and a right block that print the same statements but for signs (a
// joint about -z and one about z: `-pA + tau` against `pA + tau`, `+ t*u`
// against `- t*u`) run as one call of a signed pair: where the signs differ,
// the pair turns one lane (proxgen_rt::flip by a pair of signs from the table,
// after the constants); where they agree, the sign is printed as it was. Only
// blocks no kernel took pair so; without pairs nothing changes.
TEST(SharedBlocks, MirroredBlocksThatDifferInSignsRunAsASignedPair) {
  std::string text = onePart("left", 2, "right", 4);
  const std::string negated = "w.u_right[0] = -w.pA_right[5]", subtracted = "w.IA_base[4] + t4*";
  text.replace(text.find(negated), negated.size(), "w.u_right[0] = w.pA_right[5]");
  text.replace(text.find(subtracted), subtracted.size(), "w.IA_base[4] - t4*");
  const SharedParts s = shareBlocks(text, members({"left", "right"}), all, true);
  ASSERT_EQ(s.kernels.size(), 1u) << s.parts;
  EXPECT_EQ(s.kernels[0].pairs, 1);
  EXPECT_EQ(s.kernels[0].signs, 2);  // the banner's "mirrored: 2 signs turned in one lane"
  EXPECT_EQ(s.kernels[0].blocks.size(), 2u);
  EXPECT_EQ(test::occurrences(s.parts, "void shared_0("), 0) << s.parts;
  EXPECT_NE(s.parts.find("// 2 blocks of the same code but for 2 signs (mirrored: turned in one lane), two at a "
                         "time: left, right."),
            std::string::npos)
      << s.parts;
  // Constants {a0, b0, a1, b1}, then the signs of the two differing slots.
  EXPECT_NE(s.parts.find("alignas(2 * sizeof(Scalar)) constexpr Scalar shared_0_p0[8] = {0.25, -0.5, -1.5e-05, "
                         "-1.5e-05, -1, 1, 1, -1};"),
            std::string::npos)
      << s.parts;
  EXPECT_NE(s.parts.find("  proxgen_rt::scatter2<Scalar>(proxgen_rt::flip(proxgen_rt::pair_at(k, 2), "
                         "proxgen_rt::gather2(pA_m3_a[0], pA_m3_b[0])) + proxgen_rt::gather2(tau_a[0], tau_b[0]), "
                         "u_m2_a[0], u_m2_b[0]);"),
            std::string::npos)
      << s.parts;
  EXPECT_NE(s.parts.find(" + proxgen_rt::flip(proxgen_rt::pair_at(k, 3), x0*proxgen_rt::gather2(u_m2_a[0], "
                         "u_m2_b[0])) + proxgen_rt::pair_at(k, 1)*proxgen_rt::gather2(tau_a[1], tau_b[1]), "),
            std::string::npos)
      << s.parts;
  EXPECT_NE(s.parts.find("  shared_0_x2(shared_0_p0, &tau[2], &tau[4], "), std::string::npos) << s.parts;
  EXPECT_EQ(test::occurrences(s.parts, "w.Dinv_"), 2);
  // Without pairs the two blocks are two texts: no kernel.
  const SharedParts single = shareBlocks(text, members({"left", "right"}), all, false);
  EXPECT_TRUE(single.kernels.empty());
  EXPECT_EQ(single.parts, text);
  // A block that also multiplies where the other adds is no mirror.
  std::string other = text;
  other.replace(other.find("t4*w.u_right[0]"), 15, "t4/w.u_right[0]");
  EXPECT_TRUE(shareBlocks(other, members({"left", "right"}), all, true).kernels.empty());
}

// Which solvers share: the ones whose entry points' code is above the first-level
// instruction cache (kSharedBlocksMinOps): Solo's legs, not the iiwa (no group
// would pay there: measured 1.01-1.06 of the time, docs/benchmarks.md).
TEST(SharedBlocks, SoloSharesItsLegsTheIiwaNothing) {
  PROXGEN_REQUIRE_MODELS();
  const std::string cases = test::modelsDir() + "/cases.yaml";
  const SolverFiles solo = generateCase(cases, "solo_f3x4", "", ScalarType::Double);
  const SolverFiles iiwa = generateCase(cases, "iiwa_h3", "", ScalarType::Double);
  EXPECT_EQ(test::occurrences(iiwa.source, "shared_"), 0);
  EXPECT_EQ(iiwa.unsharedSource, iiwa.source);
  EXPECT_GT(test::occurrences(solo.source, "PROXGEN_RT_NOINLINE void shared_"), 4);
  // The banner says which blocks share a kernel; the four legs' lower links do.
  EXPECT_NE(solo.source.find("// Shared blocks"), std::string::npos);
  EXPECT_NE(solo.source.find("blocks of FL_LOWER_LEG, FR_LOWER_LEG, HL_LOWER_LEG, HR_LOWER_LEG"), std::string::npos);
  // The lane code is cut from the source without them.
  EXPECT_EQ(test::occurrences(solo.unsharedSource, "shared_"), 0);
  EXPECT_NE(solo.unsharedSource, solo.source);
}

}  // namespace
}  // namespace proxgen::emit
