// SHA-256 (emit/hash.hpp) against the FIPS 180-2 / NIST CSRC example vectors.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "emit/hash.hpp"
#include "model/error.hpp"

namespace proxgen::emit {
namespace {

TEST(Sha256, FipsVectors) {
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256Hex("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklmnopqklmnopqrlmnopqrs"
                      "mnopqrstnopqrstu"),
            "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
  EXPECT_EQ(sha256Hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Lengths around the 55/56/64-byte padding boundaries, fed whole and in pieces:
// the streaming interface must give the one-shot digest.
TEST(Sha256, PaddingBoundariesAndStreaming) {
  for (std::size_t n : {55u, 56u, 57u, 63u, 64u, 65u, 119u, 120u, 128u}) {
    const std::string s(n, 'x');
    Sha256 h;
    for (std::size_t k = 0; k < n; k += 7) h.update(s.substr(k, 7));
    std::string hex;
    for (std::uint8_t b : h.finish()) {
      char buf[3];
      std::snprintf(buf, sizeof buf, "%02x", b);
      hex += buf;
    }
    EXPECT_EQ(hex, sha256Hex(s)) << n;
  }
  // Distinct lengths give distinct digests (a wrong length field would collide them).
  EXPECT_NE(sha256Hex(std::string(55, 'x')), sha256Hex(std::string(56, 'x')));
}

TEST(Sha256, FilesHashTheirBytes) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() / "proxgen_test_sha256.bin";
  {
    std::ofstream out(p, std::ios::binary);
    out << "abc";
  }
  EXPECT_EQ(sha256File(p.string(), "URDF"), sha256Hex("abc"));
  std::filesystem::remove(p);
  // The loaders' message: the kind of file and the system's reason.
  try {
    sha256File(p.string(), "URDF");
    ADD_FAILURE() << "a missing file was hashed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open the URDF file: No such file or directory"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace proxgen::emit
