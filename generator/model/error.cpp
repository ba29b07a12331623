#include "model/error.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

namespace proxgen {

std::string describe(const std::string& file, const std::string& element, const std::string& what) {
  if (element.empty()) return fmt::format("{}: {}", file, what);
  return fmt::format("{}: {}: {}", file, element, what);
}

void fail(const std::string& file, const std::string& element, const std::string& what) {
  throw Error(describe(file, element, what));
}

namespace {

// Length of the well-formed UTF-8 sequence at text[k] (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF), its code point in *cp; 0 if
// the byte there does not start one.
std::size_t utf8Sequence(const std::string& text, std::size_t k, char32_t* cp) {
  const auto at = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char c = at(k);
  std::size_t n = 0;
  char32_t lo = 0x80, hi = 0xBF;  // range of the second byte
  if (c >= 0xC2 && c <= 0xDF) n = 2;
  else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;
    if (c == 0xED) hi = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (k + n > text.size()) return 0;
  if (at(k + 1) < lo || at(k + 1) > hi) return 0;
  for (std::size_t i = 2; i < n; ++i)
    if (at(k + i) < 0x80 || at(k + i) > 0xBF) return 0;
  char32_t v = c & (0xFF >> (n + 1));
  for (std::size_t i = 1; i < n; ++i) v = (v << 6) | (at(k + i) & 0x3F);
  *cp = v;
  return n;
}

// Code points a terminal acts on instead of showing: C1 controls (U+009B is
// CSI, as ESC [ is), line and paragraph separators, and the bidirectional
// overrides and isolates that reorder what follows them on the line.
bool isInvisibleControl(char32_t cp) {
  return (cp >= 0x80 && cp <= 0x9F) || cp == 0x061C || cp == 0x200E || cp == 0x200F || cp == 0x2028 ||
         cp == 0x2029 || (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069) || cp == 0xFEFF;
}

// The one escaping of every message: control characters (C0, DEL, C1, the
// invisible formatting above) and bytes that are not UTF-8 as \xNN (\u{...}
// for a code point above U+00FF), printable UTF-8 as it is; with `quotes`,
// also ' and \ escaped (the text goes between quotes). Cut after `maxShown`
// characters, the byte count noted. Returns true when cut.
bool appendEscaped(std::string& out, const std::string& text, std::size_t maxShown, bool quotes) {
  std::size_t shown = 0;
  for (std::size_t k = 0; k < text.size();) {
    if (shown == maxShown) {
      out += fmt::format("...{} ({} bytes)", quotes ? "'" : "", text.size());
      return true;
    }
    const unsigned char c = static_cast<unsigned char>(text[k]);
    ++shown;
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7f) out += fmt::format("\\x{:02x}", c);
      else if (quotes && (c == '\'' || c == '\\')) out += fmt::format("\\{}", char(c));
      else out += char(c);
      ++k;
      continue;
    }
    char32_t cp = 0;
    const std::size_t n = utf8Sequence(text, k, &cp);
    if (n == 0) {
      out += fmt::format("\\x{:02x}", c);
      ++k;
    } else if (isInvisibleControl(cp)) {
      out += cp <= 0xFF ? fmt::format("\\x{:02x}", unsigned(cp)) : fmt::format("\\u{{{:04x}}}", unsigned(cp));
      k += n;
    } else {
      out.append(text, k, n);
      k += n;
    }
  }
  return false;
}

}  // namespace

std::string quoted(const std::string& name) {
  std::string out = "'";
  if (appendEscaped(out, name, 80, true)) return out;
  return out + "'";
}

std::string oneLine(const std::string& text, std::size_t maxShown) {
  std::string out;
  appendEscaped(out, text, maxShown, false);
  return out;
}

std::size_t editDistance(const std::string& a0, const std::string& b0) {
  const std::string a = a0.substr(0, 100), b = b0.substr(0, 100);
  // Optimal string alignment: three rows of the dynamic programme.
  std::vector<std::size_t> before(b.size() + 1), prev(b.size() + 1), row(b.size() + 1);
  std::iota(prev.begin(), prev.end(), std::size_t(0));
  for (std::size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t change = a[i - 1] == b[j - 1] ? 0 : 1;
      row[j] = std::min({prev[j] + 1, row[j - 1] + 1, prev[j - 1] + change});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) row[j] = std::min(row[j], before[j - 2] + 1);
    }
    before.swap(prev);
    prev.swap(row);
  }
  return prev[b.size()];
}

std::vector<std::string> closestNames(const std::string& name, const std::vector<std::string>& candidates,
                                      std::size_t count) {
  std::vector<std::pair<std::size_t, std::size_t>> ranked;  // (distance, position)
  for (std::size_t k = 0; k < candidates.size(); ++k) ranked.emplace_back(editDistance(name, candidates[k]), k);
  std::stable_sort(ranked.begin(), ranked.end());
  std::vector<std::string> out;
  for (std::size_t k = 0; k < ranked.size() && out.size() < count; ++k) {
    const std::string& c = candidates[ranked[k].second];
    if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  }
  return out;
}

std::string quotedList(const std::vector<std::string>& names, const char* lastJoin) {
  std::string out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (k > 0) out += k + 1 == names.size() ? lastJoin : ", ";
    out += quoted(names[k]);
  }
  return out;
}

}  // namespace proxgen
