// `proxgen generate --batch W` and `proxgen verify --batch W` as a user runs
// them (the binary): --batch adds NAME_batch.hpp and NAME_batch.cpp and leaves
// NAME.hpp and NAME.cpp byte for byte what they are without it (the checked-in
// examples); a width that is not 2, 4, 8 or 16, or a function list without
// both solvers, is refused with one line and nothing written; verify --batch
// compares every lane with the scalar solver (docs/batch.md).
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

TEST_F(BatchCli, AWidthOtherThan2_4_8_16IsRefusedAndNothingIsWritten) {
  for (const char* width : {"3", "32", "0", "-4", "four"}) {
    const ProcessResult r = runProxgen(armGenerate({"--batch", width}));
    EXPECT_NE(r.code, 0) << width;
    EXPECT_NE(r.err.find("--batch"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    EXPECT_TRUE(listing(out_).empty()) << width;
  }
}

TEST_F(BatchCli, BatchNeedsBothSolversInTheFunctionList) {
  const ProcessResult r = runProxgen(armGenerate({"--batch", "2", "--functions", "mass_matrix"}));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("constrained_aba and prox_pv"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_TRUE(listing(out_).empty());
}

TEST_F(BatchCli, VerifyBatchComparesEveryLaneWithTheScalarSolver) {
  const ProcessResult r = runProxgen({"verify", arm_ + "/arm.urdf", "--layout", arm_ + "/layout.yaml", "--samples", "3",
                                      "--batch", "2"});
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  // 3 states x 2 mu x 4 K = 24 trials in 8 groups of 3 (mu, K): per group and
  // solver, 3 states through _many and 2 lanes through _batch, each nv + nc = 12 answers.
  EXPECT_NE(r.out.find("batched (--batch 2) vs scalar, bit for bit: 960 answers, 0 differ  ok"), std::string::npos)
      << r.out;
}

}  // namespace
