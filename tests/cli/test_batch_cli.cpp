// `proxgen generate --batch W` and `proxgen verify --batch W` as a user runs
// them (the binary): --batch adds NAME_batch.hpp and NAME_batch.cpp and leaves
// NAME.hpp and NAME.cpp byte for byte what they are without it (the checked-in
// examples); a width that is not 2, 4, 8 or 16, or a function list without
// both solvers, is refused with one line and nothing written; verify --batch
// compares every lane with the scalar solver, and the library functions'
// batched forms with the scalar functions (docs/batch.md).
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include <unistd.h>

#include "support.hpp"

namespace {

namespace fs = std::filesystem;
using proxgen::test::ProcessResult;

ProcessResult runProxgen(const std::vector<std::string>& args) {
  return proxgen::test::runProgram(PROXGEN_BINARY_PATH, args);
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> out;
  if (fs::exists(dir))
    for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

class BatchCli : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() / ("proxgen_batch_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }
  std::vector<std::string> armGenerate(const std::vector<std::string>& extra) const {
    std::vector<std::string> args = {"generate", arm_ + "/arm.urdf", "--layout", arm_ + "/layout.yaml", "--out",
                                     out_.string(), "--name", "arm"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  const std::string arm_ = proxgen::test::sourceDir() + "/generated/arm";
  fs::path out_;
};

TEST_F(BatchCli, BatchAddsTwoFilesAndLeavesTheScalarOnesAsTheyAre) {
  const ProcessResult r = runProxgen(armGenerate({"--batch", "4"}));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listing(out_), (std::set<std::string>{"arm.hpp", "arm.cpp", "arm_c.h", "arm_c.cpp", "arm_batch.hpp",
                                                  "arm_batch.cpp"}));
  // generated/arm is generated without --batch (tests/cli/test_generated_fresh.cpp keeps it fresh).
  for (const char* file : {"arm.hpp", "arm.cpp", "arm_c.h", "arm_c.cpp"})
    EXPECT_EQ(proxgen::test::slurp(out_ / file), proxgen::test::slurp(arm_ + "/" + file)) << file;
  const std::string header = proxgen::test::slurp(out_ / "arm_batch.hpp");
  EXPECT_NE(header.find("inline constexpr int batch_width = 4;"), std::string::npos);
  for (const char* entry : {"void constrained_aba_batch(", "void prox_pv_batch(", "void constrained_aba_many(",
                            "void prox_pv_many(", "struct BatchWorkspace {"})
    EXPECT_NE(header.find(entry), std::string::npos) << entry;
  // Deterministic: the same bytes a second time.
  const std::string source = proxgen::test::slurp(out_ / "arm_batch.cpp");
  ASSERT_EQ(runProxgen(armGenerate({"--batch", "4"})).code, 0);
  EXPECT_EQ(proxgen::test::slurp(out_ / "arm_batch.cpp"), source);
}

// A bad width, numeric or not, is one line naming the option and the valid
// widths (command-line values: "command line" as the file, exit 1; docs/cli.md
// "Errors"), for generate and verify alike, before any work: nothing written.
TEST_F(BatchCli, AWidthOtherThan2_4_8_16IsRefusedAndNothingIsWritten) {
  const std::string expected = "proxgen: error: command line: --batch: the lane width W is 2, 4, 8 or 16, got ";
  for (const char* width : {"3", "32", "0", "-4", "four", "x", "", "4x", " 4", "04"}) {
    const ProcessResult r = runProxgen(armGenerate({"--batch", width}));
    EXPECT_EQ(r.code, 1) << width << ": " << r.err;
    EXPECT_EQ(r.err, expected + "'" + width + "'\n") << width;
    EXPECT_TRUE(listing(out_).empty()) << width;
    const ProcessResult v = runProxgen({"verify", arm_ + "/arm.urdf", "--layout", arm_ + "/layout.yaml", "--batch", width});
    EXPECT_EQ(v.code, 1) << width << ": " << v.err;
    EXPECT_EQ(v.err, expected + "'" + width + "'\n") << width;
    EXPECT_TRUE(v.out.empty()) << v.out;
  }
}

TEST_F(BatchCli, BatchNeedsBothSolversInTheFunctionList) {
  const ProcessResult r = runProxgen(armGenerate({"--batch", "2", "--functions", "mass_matrix"}));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("constrained_aba and prox_pv"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_TRUE(listing(out_).empty());
}

// verify --batch: every lane of the solvers and, the library functions
// selected, of their _batch and _many forms against the scalar ones (one run:
// each run compiles the solver twice).
TEST_F(BatchCli, VerifyBatchComparesEveryLaneWithTheScalarSolver) {
  const ProcessResult r = runProxgen(
      {"verify", arm_ + "/arm.urdf", "--layout", arm_ + "/layout.yaml", "--samples", "3", "--batch", "2", "--functions",
       "constrained_aba,prox_pv,inverse_dynamics,nonlinear_effects,mass_matrix,mass_matrix_inverse,"
       "constraint_placements,constraint_jacobian,constraint_drift,delassus,delassus_inverse,constraint_wrenches"});
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  // 3 states x 2 mu x 4 K = 24 trials in 8 groups of 3 (mu, K): per group and
  // solver, 3 states through _many and 2 lanes through _batch, each nv + nc =
  // 12 answers: 960. Then per library function 3 samples
  // through _many and 2 lanes through _batch, 5 x its output size: the arm has
  // nv = 6, nc = 6, one constraint, so tau 6, h 6, M 36, Minv 36, X 12, J 36,
  // gamma 6, G 36, Ginv 36, W 6: 216 values, 1080 answers; 2040 in all.
  EXPECT_NE(r.out.find("batched (--batch 2) vs scalar, bit for bit: 2040 answers, 0 differ  ok"), std::string::npos)
      << r.out;
}

// The header declares the library functions' batched forms when they are
// selected, and not otherwise (the solvers-only files are those above).
TEST_F(BatchCli, TheLibraryFunctionsGetBatchedFormsWhenSelected) {
  ASSERT_EQ(runProxgen(armGenerate({"--batch", "4"})).code, 0);
  const std::string plain = proxgen::test::slurp(out_ / "arm_batch.hpp");
  EXPECT_EQ(plain.find("_many(int n, const Scalar* q, BatchWorkspace& w, Scalar* M)"), std::string::npos);
  EXPECT_EQ(plain.find("batch_out_size"), std::string::npos);
  const ProcessResult r = runProxgen(armGenerate({"--batch", "4", "--functions", "constrained_aba,prox_pv,mass_matrix"}));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string header = proxgen::test::slurp(out_ / "arm_batch.hpp");
  EXPECT_NE(header.find("void mass_matrix_batch(const Scalar* q, BatchWorkspace& w, Scalar* M) noexcept;"),
            std::string::npos);
  EXPECT_NE(header.find("void mass_matrix_many(int n, const Scalar* q, BatchWorkspace& w, Scalar* M) noexcept;"),
            std::string::npos);
  EXPECT_EQ(header.find("inverse_dynamics_batch"), std::string::npos);  // not selected
}

}  // namespace
