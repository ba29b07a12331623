// The solvers checked in under generated/ are what the current generator writes
// for the inputs beside them, byte for byte. When the generator, the templates
// or an input changes, this fails until they are regenerated with the command
// printed below.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "support.hpp"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class GeneratedFresh : public ::testing::TestWithParam<const char*> {};

TEST_P(GeneratedFresh, CheckedInFilesMatchTheGenerator) {
  const std::string robot = GetParam();
  const fs::path dir = fs::path(proxgen::test::sourceDir()) / "generated" / robot;
  const fs::path out = fs::path(::testing::TempDir()) / ("proxgen-fresh-" + robot);
  fs::remove_all(out);
  const std::string cmd = std::string("\"") + PROXGEN_BINARY_PATH + "\" generate \"" + (dir / (robot + ".urdf")).string() +
                          "\" --layout \"" + (dir / "layout.yaml").string() + "\" --out \"" + out.string() +
                          "\" --name " + robot + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  for (const std::string ext : {".hpp", ".cpp"}) {
    const std::string file = robot + ext;
    ASSERT_TRUE(fs::exists(dir / file)) << "generated/" << robot << "/" << file << " is not checked in";
    EXPECT_TRUE(slurp(out / file) == slurp(dir / file))
        << "generated/" << robot << "/" << file << " is stale; regenerate with:\n  proxgen generate generated/" << robot
        << "/" << robot << ".urdf --layout generated/" << robot << "/layout.yaml --out generated/" << robot
        << " --name " << robot;
  }
  fs::remove_all(out);
}

INSTANTIATE_TEST_SUITE_P(Examples, GeneratedFresh, ::testing::Values("arm", "quadruped", "humanoid"));

}  // namespace
