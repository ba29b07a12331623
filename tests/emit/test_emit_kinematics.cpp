// The kinematics pass's choice of sine and cosine (emit/pass_kinematics.cpp,
// sincosFunction): the runtime's sincos inlined at each revolute joint, or its
// called form on a robot of more than 16 revolute joints, where one copy of
// the kernel beats one per joint (docs/benchmarks.md, "sincos called on the
// larger robots"). The two give the same bits (tests/runtime); this checks
// which one the generated source uses, and that every joint uses it.
#include <gtest/gtest.h>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "emit/generate.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

namespace fs = std::filesystem;

// The generated source for a fixed-base chain of `links` links (links - 1 revolute joints).
std::string chainSource(int links) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("proxgen_emit_kinematics_{}_{}", getpid(), links);
  fs::create_directories(dir);
  std::ofstream(dir / "chain.urdf") << test::syntheticTreeUrdf(links, 1);
  std::ofstream(dir / "fixed.yaml") << "base: fixed\n";
  GenerateOptions g;
  g.urdf = (dir / "chain.urdf").string();
  g.layout = (dir / "fixed.yaml").string();
  g.name = "chain";
  const std::string source = generateFiles(g).source;
  fs::remove_all(dir);
  return source;
}

long count(const std::string& text, const std::string& what) {
  long n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

TEST(KinematicsCode, SinCosIsCalledFromSeventeenRevoluteJointsOn) {
  const std::string sixteen = chainSource(17), seventeen = chainSource(18);
  EXPECT_EQ(count(sixteen, "proxgen_rt::sincos(q["), 16);
  EXPECT_EQ(count(sixteen, "proxgen_rt::sincos_noinline("), 0);
  EXPECT_EQ(count(seventeen, "proxgen_rt::sincos_noinline(q["), 17);
  EXPECT_EQ(count(seventeen, "proxgen_rt::sincos("), 0);
}

}  // namespace
}  // namespace proxgen::emit
