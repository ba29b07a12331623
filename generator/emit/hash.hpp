// SHA-256 (FIPS 180-4), small and self-contained: the generated files record
// the hashes of their input files so a reader can tell which inputs made them.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace proxgen::emit {

class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t size);
  void update(const std::string& s) { update(s.data(), s.size()); }
  /// The digest; the object must not be updated afterwards.
  std::array<std::uint8_t, 32> finish();

 private:
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buf_{};
  std::size_t used_ = 0;
  std::uint64_t bytes_ = 0;
};

/// Lower-case hex SHA-256 of a byte string.
std::string sha256Hex(const std::string& bytes);

/// Lower-case hex SHA-256 of a file's contents, read as readInputFile reads
/// it (`kind` names the file in its message); throws proxgen::Error if unreadable.
std::string sha256File(const std::string& path, const char* kind);

}  // namespace proxgen::emit
