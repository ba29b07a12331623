// Names from a URDF or a layout reach generated code only as sanitised
// identifiers (emit/identifiers.hpp) or escaped comment text: whatever a name
// holds, the result is a safe identifier, and no comment can be broken out of.
#include <gtest/gtest.h>

#include <cctype>
#include <random>
#include <set>
#include <string>

#include "emit/identifiers.hpp"

namespace proxgen::emit {
namespace {

// Every property sanitizeIdentifier promises.
void expectSafeIdentifier(const std::string& id, const std::string& from) {
  ASSERT_FALSE(id.empty()) << from;
  EXPECT_TRUE(std::isalpha(static_cast<unsigned char>(id[0]))) << id << " from " << from;
  for (char c : id) EXPECT_TRUE(std::isalnum(static_cast<unsigned char>(c)) || c == '_') << id << " from " << from;
  EXPECT_EQ(id.find("__"), std::string::npos) << id;
  EXPECT_NE(id.back(), '_') << id;
  EXPECT_LE(id.size(), kMaxIdentifierLength) << id;  // "kw_" included
  EXPECT_FALSE(isReservedIdentifier(id)) << id;
}

// Every property escapeComment promises.
void expectSafeComment(const std::string& text, const std::string& from) {
  for (char c : text) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "byte " << int(static_cast<unsigned char>(c)) << " from " << from;
  EXPECT_EQ(text.find("*/"), std::string::npos) << text;
  EXPECT_EQ(text.find("/*"), std::string::npos) << text;
  EXPECT_EQ(text.find("??"), std::string::npos) << text;
  // Every backslash starts an \xNN escape, so none can end a line.
  for (std::size_t k = text.find('\\'); k != std::string::npos; k = text.find('\\', k + 1))
    EXPECT_EQ(text.compare(k, 2, "\\x"), 0) << text;
}

TEST(Identifiers, KeepPlainNames) {
  EXPECT_EQ(sanitizeIdentifier("LF_thigh"), "LF_thigh");
  EXPECT_EQ(sanitizeIdentifier("arm_left_1_link"), "arm_left_1_link");
}

TEST(Identifiers, KeywordsAndMacrosGetAPrefix) {
  for (const char* kw : {"for", "class", "int", "delete", "namespace", "and", "xor_eq", "std", "NAN", "assert", "main"}) {
    EXPECT_EQ(sanitizeIdentifier(kw), std::string("kw_") + kw);
    expectSafeIdentifier(sanitizeIdentifier(kw), kw);
  }
}

// Issue 19 item 8: names of the C and C++ libraries (functions, types,
// objects, macros, the families the standards reserve) as a namespace do not
// compile; they get the prefix, and the prefixed name is free. Whether the
// list is complete is checked with the compiler in tests/cli/test_reserved_names.cpp.
TEST(Identifiers, LibraryNamesAndReservedFamiliesGetAPrefix) {
  for (const char* n : {"j1", "log", "gamma", "size_t", "M_PI_2", "sin", "strlen", "FILE", "tm", "errno", "stdin",
                        "printf", "environ", "proxgen_rt", "Scalar", "Settings", "Workspace",
                        // families: POSIX *_t, E*, M_*, INT*_MAX, PRI*, SIG*
                        "my_type_t", "EFOOBAR", "M_SOMETHING", "INT24_MAX", "UINT_LEAST24_MAX", "PRIdFOO", "SIGFOO"}) {
    EXPECT_TRUE(isReservedIdentifier(n)) << n;
    EXPECT_EQ(sanitizeIdentifier(n), std::string("kw_") + n);
    expectSafeIdentifier(sanitizeIdentifier(n), n);
  }
  // Ordinary robot names stay as they are.
  for (const char* n : {"arm", "LF_thigh", "base_link", "torso", "Elbow", "elbow", "Mass", "interval", "signalling"})
    EXPECT_EQ(sanitizeIdentifier(n), n);
}

TEST(Identifiers, LeadingDigitsAndUnderscores) {
  EXPECT_EQ(sanitizeIdentifier("1st_link"), "n1st_link");
  EXPECT_EQ(sanitizeIdentifier("__reserved"), "reserved");
  EXPECT_EQ(sanitizeIdentifier("_Upper"), "Upper");
  EXPECT_EQ(sanitizeIdentifier("a__b__"), "a_b");
  EXPECT_EQ(sanitizeIdentifier(""), "unnamed");
  EXPECT_EQ(sanitizeIdentifier("***"), "unnamed");
}

TEST(Identifiers, CommentTerminatorsNewlinesTrigraphsUnicode) {
  const std::string nasty[] = {"*/ int main() { return 1; } /*", "line1\n#include <cstdlib>\n", "??/ ??= ??( ??) trigraphs",
                               "\xc5\x82\xc4\x85""cze_\xe6\x97\xa5\xe6\x9c\xac_\xf0\x9f\xa4\x96", "tab\tcr\rend\\",
                               "%s %n {} {0} {:x}"};
  for (const std::string& n : nasty) {
    expectSafeIdentifier(sanitizeIdentifier(n), n);
    expectSafeComment(escapeComment(n), n);
  }
  EXPECT_EQ(sanitizeIdentifier("*/ int main() { return 1; } /*"), "int_main_return_1");
  EXPECT_EQ(escapeComment("a*/b"), "a*\\x2fb");
  EXPECT_EQ(escapeComment("x??/"), "x?\\x3f/");
  EXPECT_EQ(escapeComment("end\\"), "end\\x5c");
  EXPECT_EQ(escapeComment("a\nb"), "a\\x0ab");
  EXPECT_EQ(escapeComment("caf\xc3\xa9"), "caf\\xc3\\xa9");
}

TEST(Identifiers, CollisionsAfterSanitisingAreMadeUnique) {
  IdentifierSet ids;
  std::set<std::string> seen;
  int index = 0;
  for (const char* n : {"a-b", "a.b", "a b", "a_b", "a_b_3"}) {
    const std::string id = ids.make(n, ++index);
    expectSafeIdentifier(id, n);
    EXPECT_TRUE(seen.insert(id).second) << n << " -> " << id << " twice";
  }
  // The first keeps the plain form, the others carry the index they were given.
  IdentifierSet again;
  EXPECT_EQ(again.make("a-b", 1), "a_b");
  EXPECT_EQ(again.make("a.b", 2), "a_b_2");
}

TEST(Identifiers, TenKilobyteNamesAreCut) {
  std::string unit = "long*/??/\\\"\xc3\xa9_";
  std::string name;
  while (name.size() < 10240) name += unit;
  const std::string id = sanitizeIdentifier(name);
  expectSafeIdentifier(id, "10 kB name");
  EXPECT_LE(id.size(), kMaxIdentifierLength);
  const std::string text = escapeComment(name);
  expectSafeComment(text, "10 kB name");
  EXPECT_LE(text.size(), 4 * kMaxCommentLength + 32);  // at most one 4-byte escape per kept byte, plus the note
  EXPECT_NE(text.find(std::to_string(name.size()) + " bytes"), std::string::npos) << text;
}

// A uniqueness suffix can make a reserved name: "M" taken, "M_2" is one of the
// math constants' family M_* (a fuzz_identifiers finding).
TEST(Identifiers, ASuffixedNameIsNeverReserved) {
  IdentifierSet set;
  EXPECT_EQ(set.make("M", 1), "M");
  const std::string second = set.make("M", 2);
  expectSafeIdentifier(second, "the second M");
  EXPECT_EQ(second, "kw_M_2");
}

// A reserved family's long name: the prefix counts against the length
// (fuzz_identifiers found "FP_" followed by 45 letters giving 51 characters).
TEST(Identifiers, AReservedLongNameStaysWithinTheLengthWithItsPrefix) {
  const std::string name = "FP_" + std::string(kMaxIdentifierLength, 'O');
  const std::string id = sanitizeIdentifier(name);
  expectSafeIdentifier(id, name);
  EXPECT_EQ(id, "kw_FP_" + std::string(kMaxIdentifierLength - 6, 'O'));
}

// Random byte strings: the properties hold for every input, not just the ones above.
TEST(Identifiers, RandomBytesAlwaysGiveSafeOutput) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> byte(0, 255), len(0, 80);
  IdentifierSet ids;
  std::set<std::string> seen;
  for (int n = 0; n < 2000; ++n) {
    std::string s(std::size_t(len(rng)), ' ');
    for (char& c : s) c = char(byte(rng));
    expectSafeIdentifier(sanitizeIdentifier(s), "random");
    expectSafeComment(escapeComment(s), "random");
    EXPECT_TRUE(seen.insert(ids.make(s, n)).second);
  }
}

}  // namespace
}  // namespace proxgen::emit
