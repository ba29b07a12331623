// Time and peak memory of the `proxgen` binary at every documented input limit
// (docs/guarantees.md, "Resource bounds"): each input is written at (or just
// past) its limit, proxgen runs as a child process, and its CPU time and peak
// resident memory come from wait4(). The bounds asserted are the documented
// ones: loading takes seconds and under 0.7 GB. The measured figures are
// printed as `[ bounds ]` lines, the numbers in the table of docs/guarantees.md.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "model/layout.hpp"
#include "model/state.hpp"
#include "model/urdf.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::TempFile;

// The documented bounds. Memory: "under 0.7 GB". Time: "seconds"; 20 s of CPU
// is the assertion, far above the measured figures (the table) so that a
// loaded machine cannot fail it, and far below the 24 s one quadratic
// element took, or the minutes a 10,000-deep cycle walk took.
constexpr double kMaxPeakBytes = 0.7e9;
constexpr double kMaxCpuSeconds = 20.0;

struct ChildRun {
  int status = -1;  // exit status, -1 if killed
  double cpuSeconds = 0, peakBytes = 0;
  std::string err;
};

// Runs proxgen with `args`, stdout to /dev/null, stderr to a file.
ChildRun runProxgen(const std::vector<std::string>& args) {
  TempFile err("stderr.txt");
  err.write("");
  std::vector<std::string> argv = {PROXGEN_BINARY_PATH};
  argv.insert(argv.end(), args.begin(), args.end());
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open("/dev/null", O_WRONLY);
    const int e = ::open(err.path().c_str(), O_WRONLY | O_TRUNC);
    ::dup2(out, 1);
    ::dup2(e, 2);
    std::vector<char*> cargv;
    for (std::string& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    ::execv(cargv[0], cargv.data());
    ::_exit(127);
  }
  ChildRun r;
  int status = 0;
  struct rusage ru {};
  if (::wait4(pid, &status, 0, &ru) != pid) return r;
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.cpuSeconds = double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  r.peakBytes = 1024.0 * double(ru.ru_maxrss);  // Linux: kilobytes
  r.err = test::slurp(err.path());
  return r;
}

void expectWithinBounds(const ChildRun& r, const std::string& label, double maxCpuSeconds = kMaxCpuSeconds) {
  std::printf("[ bounds   ] %s: exit %d, %.2f s CPU, %.0f MB peak\n", label.c_str(), r.status, r.cpuSeconds, r.peakBytes / 1e6);
  EXPECT_LE(r.peakBytes, kMaxPeakBytes) << label;
  EXPECT_LE(r.cpuSeconds, maxCpuSeconds) << label;
  EXPECT_GE(r.status, 0) << label << " did not exit: " << r.err;
  EXPECT_LE(r.status, 1) << label << ": " << r.err;  // 0 or a clear error, never an internal one (3)
}



std::size_t countOf(const std::string& s, char c) { return std::size_t(std::count(s.begin(), s.end(), c)); }

TEST(Bounds, UrdfAtEveryLimit) {
  PROXGEN_SKIP_UNDER_SANITIZER();
  TempFile f("bounds.urdf");
  const std::string base = test::syntheticTreeUrdf(int(kMaxUrdfLinks), 3);
  // Links: 4096, the limit, accepted.
  {
    const ChildRun r = runProxgen({"check", f.write(base)});
    EXPECT_EQ(r.status, 0) << r.err;
    expectWithinBounds(r, "URDF 4096-link tree");
  }
  // Bytes: the same tree padded with a comment to kMaxUrdfBytes.
  {
    const std::size_t fill = kMaxUrdfBytes - base.size() - 16;
    const std::string xml = test::syntheticTreeUrdf(int(kMaxUrdfLinks), 3, "<!--" + std::string(fill, 'x') + "-->\n");
    ASSERT_LE(xml.size(), kMaxUrdfBytes);
    const ChildRun r = runProxgen({"check", f.write(xml)});
    EXPECT_EQ(r.status, 0) << r.err;
    expectWithinBounds(r, fmt::format("URDF 4096-link tree + comment, {} bytes", xml.size()));
  }
  // Tags: padded with empty elements to kMaxUrdfTags '<', every one a DOM node in both parsers.
  {
    const std::size_t have = countOf(base, '<') + 2;  // <gazebo> and </gazebo>
    std::string pad = "<gazebo>";
    for (std::size_t k = have; k < kMaxUrdfTags; ++k) pad += "<a/>";
    pad += "</gazebo>\n";
    const std::string xml = test::syntheticTreeUrdf(int(kMaxUrdfLinks), 3, pad);
    ASSERT_EQ(countOf(xml, '<'), kMaxUrdfTags);
    const ChildRun r = runProxgen({"check", f.write(xml)});
    EXPECT_EQ(r.status, 0) << r.err;
    expectWithinBounds(r, fmt::format("URDF 4096-link tree + empty elements, {} tags, {} bytes", kMaxUrdfTags, xml.size()));
  }
  // Attributes: padded with elements of 64 attributes to kMaxUrdfAttributes.
  {
    const std::size_t have = countOf(base, '=');
    std::string pad = "<gazebo>";
    std::size_t attributes = have;
    while (attributes + kMaxXmlAttributesPerElement <= kMaxUrdfAttributes) {
      pad += "<a";
      for (std::size_t k = 0; k < kMaxXmlAttributesPerElement; ++k) pad += fmt::format(" a{}=\"\"", k);
      pad += "/>";
      attributes += kMaxXmlAttributesPerElement;
    }
    pad += "</gazebo>\n";
    const std::string xml = test::syntheticTreeUrdf(int(kMaxUrdfLinks), 3, pad);
    const ChildRun r = runProxgen({"check", f.write(xml)});
    EXPECT_EQ(r.status, 0) << r.err;
    expectWithinBounds(r, fmt::format("URDF 4096-link tree + {} attributes, {} bytes", attributes, xml.size()));
  }
  // Depth: a chain of 512 joints, accepted; and 80,000 attributes on one element, refused.
  {
    const ChildRun r = runProxgen({"check", f.write(test::syntheticTreeUrdf(int(kMaxTreeDepth) + 1, 1))});
    EXPECT_EQ(r.status, 0) << r.err;
    expectWithinBounds(r, "URDF 512-deep chain");
  }
  {
    std::string attrs;
    for (int k = 0; k < 80000; ++k) attrs += fmt::format(" a{}=\"\"", k);
    const ChildRun r = runProxgen({"check", f.write("<robot name=\"r\"><link name=\"a\"" + attrs + "/></robot>")});
    EXPECT_EQ(r.status, 1);
    expectWithinBounds(r, "URDF one element with 80,000 attributes (refused)");
  }
}

std::string arm() { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/arm3.urdf"; }

TEST(Bounds, LayoutAtItsLimit) {
  PROXGEN_SKIP_UNDER_SANITIZER();
  TempFile f("bounds.yaml");
  // 4 MiB of welds: refused at the row limit, after yaml-cpp has read it all.
  std::string yaml = "constraints:\n";
  for (int k = 0; yaml.size() < (4u << 20) - 64; ++k) yaml += fmt::format("  - {{name: c{}, link: tool, type: 6d}}\n", k);
  const ChildRun r = runProxgen({"check", arm(), "--layout", f.write(yaml)});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("more than 256 constraint rows"), std::string::npos) << r.err;
  expectWithinBounds(r, fmt::format("layout of {} bytes of welds (refused at row 256)", yaml.size()));
}

TEST(Bounds, StateAtItsLimits) {
  PROXGEN_SKIP_UNDER_SANITIZER();
  TempFile layout("bounds.yaml"), f("bounds.json");
  layout.write("constraints:\n  - {name: tip, link: tool, type: 3d}\n");
  // 64 MiB of nested lists: refused at the fifth level (2.4 GB as a DOM before).
  {
    const std::size_t half = (kMaxStateBytes / 2);
    const ChildRun r = runProxgen({"eval", arm(), "--layout", layout.path(), "--state",
                              f.write(std::string(half, '[') + std::string(half, ']'))});
    EXPECT_EQ(r.status, 1) << r.err;
    expectWithinBounds(r, "state of 64 MiB of nested lists (refused)");
  }
  // Just under kMaxStateValues values in objects of long keys filling 64 MiB:
  // the most DOM a state file can build before it is judged (refused: unknown joints).
  {
    const std::size_t perObject = 8000;
    const std::size_t objects = (kMaxStateValues - 8) / (perObject + 1);
    const std::size_t keyLength = kMaxStateBytes / (objects * perObject) - 8;
    std::string json = "[";
    json.reserve(kMaxStateBytes);
    for (std::size_t o = 0; o < objects; ++o) {
      json += o ? ",{" : "{";
      for (std::size_t k = 0; k < perObject; ++k)
        json += fmt::format("{}\"{:0>{}}\":0", k ? "," : "", k, keyLength);
      json += "}";
    }
    json += "]";
    ASSERT_LE(json.size(), kMaxStateBytes);
    const ChildRun r = runProxgen({"eval", arm(), "--layout", layout.path(), "--state", f.write(json)});
    EXPECT_EQ(r.status, 1) << r.err;
    expectWithinBounds(r, fmt::format("state of {} objects of {} keys, {} bytes (refused)", objects, perObject, json.size()));
  }
  // Valid states filling the value limit: each of the arm's states is 15 values.
  {
    const std::string one =
        "{\"q\":{\"shoulder\":0.1,\"elbow\":0.2,\"slide\":0.01},\"v\":{\"shoulder\":0,\"elbow\":0,\"slide\":0},"
        "\"tau\":{\"shoulder\":1,\"elbow\":0,\"slide\":0}}";
    const std::size_t states = (kMaxStateValues - 1) / 16;
    std::string json = "[";
    for (std::size_t k = 0; k < states; ++k) json += (k ? "," : "") + one;
    json += "]";
    const ChildRun r = runProxgen({"eval", arm(), "--layout", layout.path(), "--state", f.write(json)});
    EXPECT_EQ(r.status, 0) << r.err;
    // Loading is seconds; `eval` then solves and prints every state, linear in
    // their number (measured 80 us each, 21 s CPU here): 100 s is the bound
    // asserted, 400 us per state, for a loaded machine.
    expectWithinBounds(r, fmt::format("{} valid states, {} bytes, solved and printed", states, json.size()), 100.0);
  }
}

}  // namespace
}  // namespace proxgen
