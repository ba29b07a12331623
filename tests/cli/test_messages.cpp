// Every message of the `proxgen` binary is one line of escaped text with exit 1
// for bad input (issue 19 items 5, 7 and 9): paths and names holding a newline,
// ESC or a C1 control (U+009B is CSI, as ESC [ is) never reach the terminal
// raw, CLI11's own messages included; inputs that used to end in an internal
// error (exit 3) or in `null` with exit 0 are refused.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "model/error.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

namespace fs = std::filesystem;
using test::ProcessResult;
using test::TempFile;

std::string good(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/" + file; }

ProcessResult runProxgen(const std::vector<std::string>& args) { return test::runProgram(PROXGEN_BINARY_PATH, args); }

// Bytes a terminal acts on: C0 controls but the final newline, DEL, ESC, and
// the UTF-8 encodings of the C1 controls U+0080..U+009F (C2 80..C2 9F).
void expectOneEscapedLine(const ProcessResult& r, int code = 1) {
  EXPECT_EQ(r.code, code) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.back(), '\n');
  const std::string body = r.err.substr(0, r.err.size() - 1);
  for (std::size_t k = 0; k < body.size(); ++k) {
    const unsigned char c = static_cast<unsigned char>(body[k]);
    EXPECT_FALSE(c < 0x20 || c == 0x7f) << "raw control byte " << int(c) << " in " << r.err;
    if (c == 0xc2 && k + 1 < body.size()) {
      const unsigned char n = static_cast<unsigned char>(body[k + 1]);
      EXPECT_FALSE(n >= 0x80 && n <= 0x9f) << "raw C1 control in " << r.err;
    }
  }
  EXPECT_EQ(r.err.rfind("proxgen: ", 0), 0u) << r.err;
}

const std::string kHostile = "a\nb\x1b[31mred\xc2\x9b" "2J\r\x7f end";

TEST(Messages, AHostilePathIsEscaped) {
  const ProcessResult r = runProxgen({"check", kHostile + ".urdf"});
  expectOneEscapedLine(r);
  EXPECT_NE(r.err.find("a\\x0ab\\x1b[31mred\\x9b2J\\x0d\\x7f end.urdf"), std::string::npos) << r.err;
}

TEST(Messages, AHostileCaseNameIsEscaped) {
  TempFile cases(".yaml");
  cases.write("cases:\n  - {name: arm3, model: " + good("arm3.urdf") + ", base: fixed, constraints: []}\n");
  const ProcessResult r = runProxgen({"generate", "--cases", cases.path(), "--case", kHostile, "--out", "/nonexistent"});
  expectOneEscapedLine(r);
  EXPECT_NE(r.err.find("no case named"), std::string::npos) << r.err;
}

// CLI11 quotes unexpected arguments verbatim and printed them over several lines.
TEST(Messages, CommandLineSyntaxErrorsAreOneEscapedLine) {
  const ProcessResult extra = runProxgen({"check", "--", "--a", kHostile});
  expectOneEscapedLine(extra, extra.code);
  EXPECT_GE(extra.code, 100);  // CLI11's codes for syntax (docs/cli.md)
  const ProcessResult unknown = runProxgen({"check", good("arm3.urdf"), "--no-such-option" + kHostile});
  expectOneEscapedLine(unknown, unknown.code);
  EXPECT_GE(unknown.code, 100);
}

// check's summary prints names as they are, escaped: the hostile fixture's tab,
// carriage return and newline inside names reach stdout as \x09, \x0d, \x0a.
TEST(Messages, CheckSummaryEscapesHostileNames) {
  const ProcessResult r = runProxgen({"check", std::string(PROXGEN_TEST_DATA_DIR) + "/hostile/names.urdf"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (unsigned char c : r.out) EXPECT_FALSE((c < 0x20 && c != '\n') || c == 0x7f) << "raw control byte " << int(c);
  EXPECT_NE(r.out.find("tab\\x09cr\\x0dend"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("line1\\x0a#include"), std::string::npos) << r.out;
}

TEST(Messages, EscapingKeepsPrintableUtf8AndEscapesTheRest) {
  EXPECT_EQ(quoted("caf\xc3\xa9"), "'caf\xc3\xa9'");                       // printable UTF-8 kept
  EXPECT_EQ(quoted("\xc2\x9b"), "'\\x9b'");                                 // C1 CSI
  EXPECT_EQ(quoted("\xe2\x80\xae" "abc"), "'\\u{202e}abc'");                // bidi override
  EXPECT_EQ(quoted("\xff\xfe"), "'\\xff\\xfe'");                            // not UTF-8
  EXPECT_EQ(quoted("\xc0\xaf"), "'\\xc0\\xaf'");                            // overlong '/'
  EXPECT_EQ(quoted("\xed\xa0\x80"), "'\\xed\\xa0\\x80'");                   // a surrogate
  EXPECT_EQ(oneLine("it's a\\b\n"), "it's a\\b\\x0a");                     // oneLine leaves quotes alone
  EXPECT_EQ(quoted("it's"), "'it\\'s'");
}

// Issue 19 item 7: a `name` that is a list ended in a yaml-cpp conversion error (exit 3).
TEST(Messages, ACaseNameThatIsAListIsOneError) {
  TempFile cases(".yaml");
  cases.write("cases:\n  - {name: [a, b], model: " + good("arm3.urdf") + ", base: fixed, constraints: []}\n");
  const ProcessResult r = runProxgen({"generate", "--cases", cases.path(), "--case", "a", "--out", "/nonexistent"});
  expectOneEscapedLine(r);
  EXPECT_NE(r.err.find("cases[0].name"), std::string::npos) << r.err;
  const ProcessResult m = runProxgen({"verify", "--cases", cases.path(), "--case", "a"});
  expectOneEscapedLine(m);
}

// Issue 19 item 5: a state whose dynamics overflow double printed `null` and
// exited 0. Every number of this state is finite and accepted on its own; the
// velocity product v^2 = 1e320 is not a double. Whichever stage refuses it,
// the answer is one error, exit 1, nothing on stdout.
TEST(Messages, AnOverflowingStateIsAnErrorNotNull) {
  TempFile state(".json");
  state.write(R"({"q": {"shoulder": 0.1, "elbow": 0.2, "slide": 0.3}, "v": {"shoulder": 1e160, "elbow": 1e160, "slide": 1e160}})");
  for (const char* algorithm : {"caba", "pv", "ltl", "ltls", "dense"}) {
    SCOPED_TRACE(algorithm);
    const ProcessResult r = runProxgen({"eval", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--state",
                                        state.path(), "--algorithm", algorithm});
    expectOneEscapedLine(r);
    EXPECT_NE(r.err.find(state.path()), std::string::npos) << r.err;
  }
}

// --- issue 18 item 8: messages a user can act on --------------------------

// CLI11 read `proxgen chek` as a stray argument: "A subcommand is required".
// The word is named, the valid commands listed, and the near one suggested
// (editDistance("chek", "check") = 1; a prefix of a command counts as near).
TEST(Messages, AnUnknownCommandIsNamedWithTheValidOnes) {
  const std::string valid = "(valid: check, eval, generate, verify)";
  struct Case {
    std::vector<std::string> args;
    std::string expected;
  };
  for (const Case& c : {Case{{"chek", "robot.urdf"}, "unknown command 'chek' " + valid + "; did you mean 'check'?"},
                        Case{{"gen"}, "unknown command 'gen' " + valid + "; did you mean 'generate'?"},
                        Case{{"veirfy"}, "unknown command 'veirfy' " + valid + "; did you mean 'verify'?"},  // a swap is 1
                        Case{{"frobnicate"}, "unknown command 'frobnicate' " + valid}}) {
    const ProcessResult r = runProxgen(c.args);
    expectOneEscapedLine(r);
    EXPECT_EQ(r.err, "proxgen: error: command line: " + c.expected + "\n");
  }
  // What was right stays so: a known command, and no command at all (CLI11's own message).
  EXPECT_EQ(runProxgen({"--version"}).code, 0);
  EXPECT_EQ(runProxgen({"check", "--help"}).code, 0);
  const ProcessResult none = runProxgen({});
  EXPECT_GE(none.code, 100);
  EXPECT_NE(none.err.find("A subcommand is required"), std::string::npos) << none.err;
}

// A file that cannot be opened gets the system's reason, in the system's words
// (strerror of the errno open() or read() gave), and which file it was meant to be.
TEST(Messages, AFileThatCannotBeOpenedGivesTheSystemsReason) {
  TempFile regular(".urdf");
  regular.write("<robot name=\"r\"/>");
  const fs::path loop = fs::path(regular.path()).parent_path() / ("proxgen_loop_" + std::to_string(::getpid()) + ".urdf");
  fs::remove(loop);
  fs::create_symlink(loop, loop);  // a link to itself: ELOOP
  struct Case {
    std::vector<std::string> args;
    std::string file, expected;
  };
  const std::string arm = good("arm3.urdf");
  for (const Case& c : {
           Case{{"check", "/nonexistent/robot.urdf"}, "/nonexistent/robot.urdf", "cannot open the URDF file: " + std::string(std::strerror(ENOENT))},
           Case{{"check", PROXGEN_TEST_DATA_DIR}, PROXGEN_TEST_DATA_DIR, "cannot read the URDF file: " + std::string(std::strerror(EISDIR))},
           Case{{"check", regular.path() + "/robot.urdf"}, regular.path() + "/robot.urdf", "cannot open the URDF file: " + std::string(std::strerror(ENOTDIR))},
           Case{{"check", loop.string()}, loop.string(), "cannot open the URDF file: " + std::string(std::strerror(ELOOP))},
           Case{{"check", arm, "--layout", "/nonexistent.yaml"}, "/nonexistent.yaml", "cannot open the layout file: " + std::string(std::strerror(ENOENT))},
           Case{{"eval", arm, "--layout", good("arm3_tool.yaml"), "--state", PROXGEN_TEST_DATA_DIR}, PROXGEN_TEST_DATA_DIR,
                "cannot read the state file: " + std::string(std::strerror(EISDIR))}}) {
    const ProcessResult r = runProxgen(c.args);
    expectOneEscapedLine(r);
    EXPECT_EQ(r.err, "proxgen: error: " + c.file + ": " + c.expected + "\n");
  }
  fs::remove(loop);
  EXPECT_EQ(std::string(std::strerror(EISDIR)), "Is a directory");  // glibc's words, as docs/cli.md quotes them
}

// Permission denied: only where permissions bind (root reads a file of mode 000).
TEST(Messages, AnUnreadableFileSaysPermissionDenied) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: mode 000 does not stop root from reading";
  TempFile locked(".urdf");
  locked.write("<robot name=\"r\"/>");
  fs::permissions(locked.path(), fs::perms::none);
  const ProcessResult r = runProxgen({"check", locked.path()});
  expectOneEscapedLine(r);
  EXPECT_EQ(r.err, "proxgen: error: " + locked.path() + ": cannot open the URDF file: " + std::strerror(EACCES) + "\n");
}

TEST(Messages, XacroInputIsToldToRunXacro) {
  const std::string f = std::string(PROXGEN_TEST_DATA_DIR) + "/bad/xacro_macro.urdf.xacro";
  const ProcessResult r = runProxgen({"check", f});
  expectOneEscapedLine(r);
  EXPECT_NE(r.err.find("this is a xacro file, not a URDF: run xacro first (xacro " + f + " > " +
                       std::string(PROXGEN_TEST_DATA_DIR) + "/bad/xacro_macro.urdf)"),
            std::string::npos)
      << r.err;
  // generate writes nothing for it.
  const fs::path out = fs::temp_directory_path() / ("proxgen_xacro_" + std::to_string(::getpid()));
  fs::remove_all(out);
  expectOneEscapedLine(runProxgen({"generate", f, "--layout", good("arm3_tool.yaml"), "--out", out.string()}));
  EXPECT_FALSE(fs::exists(out / "arm3.hpp") || (fs::exists(out) && !fs::is_empty(out)));
  fs::remove_all(out);
}

TEST(Messages, UnknownLinkAndFreeFlyerQThroughTheBinary) {
  const std::string bad = std::string(PROXGEN_TEST_DATA_DIR) + "/bad/";
  const ProcessResult link = runProxgen({"check", good("arm3.urdf"), "--layout", bad + "unknown_link_typo.yaml"});
  expectOneEscapedLine(link);
  EXPECT_EQ(link.err, "proxgen: error: " + bad + "unknown_link_typo.yaml:5: constraints[0] 'grip': link 'uper_arm' is not in " +
                          good("arm3.urdf") + " (closest: 'upper_arm', 'forearm', 'hand')\n");  // derived in tests/model/test_bad_input.cpp
  const ProcessResult q = runProxgen({"eval", good("arm3.urdf"), "--layout", good("arm3_floating.yaml"), "--state",
                                      bad + "state_wrong_length.json"});
  expectOneEscapedLine(q);
  EXPECT_EQ(q.err, "proxgen: error: " + bad + "state_wrong_length.json: q.'root_joint': expected a list of 7 numbers [x y z qx qy "
                       "qz qw] for free-flyer joint 'root_joint' (position, then the quaternion with w last), got a list of 6\n");
}

// The distance behind every suggestion: textbook values of the optimal string
// alignment distance (Levenshtein plus swaps of neighbours).
TEST(Messages, EditDistanceAndClosestNames) {
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);  // k->s, e->i, insert g
  EXPECT_EQ(editDistance("chek", "check"), 1u);
  EXPECT_EQ(editDistance("ab", "ba"), 1u);            // one swap
  EXPECT_EQ(editDistance("ca", "abc"), 3u);           // OSA edits no substring twice (Damerau would give 2)
  EXPECT_EQ(editDistance("", "abc"), 3u);
  EXPECT_EQ(editDistance("abc", "abc"), 0u);
  // Only the first 100 bytes count: two 10 kB names differing past them are "equal".
  EXPECT_EQ(editDistance(std::string(10000, 'a'), std::string(9000, 'a') + std::string(1000, 'b')), 0u);
  EXPECT_EQ(closestNames("lf_foot", {"rf_foot", "lh_foot", "lf_foot", "base"}, 2), (std::vector<std::string>{"lf_foot", "rf_foot"}));
  // Ties keep the candidates' order; duplicates are listed once; fewer than asked is fine.
  EXPECT_EQ(closestNames("b", {"c", "a", "c"}, 3), (std::vector<std::string>{"c", "a"}));
  EXPECT_EQ(quotedList({"a", "b", "c"}), "'a', 'b' or 'c'");
}

}  // namespace
}  // namespace proxgen
