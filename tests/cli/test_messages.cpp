// Every message of the `proxgen` binary is one line of escaped text with exit 1
// for bad input (issue 19 items 5, 7 and 9): paths and names holding a newline,
// ESC or a C1 control (U+009B is CSI, as ESC [ is) never reach the terminal
// raw, CLI11's own messages included; inputs that used to end in an internal
// error (exit 3) or in `null` with exit 0 are refused.
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

}  // namespace
}  // namespace proxgen
