// Shared by the fuzz targets: what an error message must look like, and how a
// target reports a broken promise (abort, so libFuzzer saves the input).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "model/error.hpp"

namespace proxgen::fuzz {

/// Longest error message accepted from a fuzzed input. The file name and the
/// element are short here, names are cut at 80 characters by quoted(), and the
/// longest fixed texts are about 200 characters; 1024 leaves room for three
/// urdfdom messages while still catching a name or a document copied whole.
inline constexpr std::size_t kMaxMessage = 1024;

[[noreturn]] inline void broken(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz: broken promise: %s\n%s\n", what, detail.c_str());
  std::abort();
}

/// A proxgen::Error is the expected answer to bad input: it must be one line of
/// printable text and bounded (the CLI prints it as `proxgen: error: ...`).
inline void checkMessage(const proxgen::Error& e) {
  const std::string m = e.what();
  if (m.empty()) broken("empty error message", m);
  if (m.size() > kMaxMessage) broken("error message longer than kMaxMessage", m.substr(0, 2000));
  for (unsigned char c : m)
    if (c < 0x20 || c == 0x7f) broken("control character in an error message", m);
}

}  // namespace proxgen::fuzz

// Runs `body`; proxgen::Error is checked, any other exception is a finding
// (the CLI would report it as an internal error).
#define PROXGEN_FUZZ_GUARD(body)                                               \
  try {                                                                        \
    body;                                                                      \
  } catch (const proxgen::Error& e) {                                          \
    proxgen::fuzz::checkMessage(e);                                            \
  } catch (const std::exception& e) {                                          \
    proxgen::fuzz::broken("exception other than proxgen::Error", e.what());    \
  }
