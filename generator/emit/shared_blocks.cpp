// Shared blocks: the body blocks of the part functions, each rewritten into a
// canonical form (its literals -> k[i], its members -> <prefix>_m<i>, its temporaries
// -> x<i>, the integer subscripts of members and inputs relative to the
// smallest one), grouped by that form; each group of two or more becomes one
// kernel (the canonical form as a function) and a call per block with the
// block's constants, member pointers and input offsets.
#include "emit/shared_blocks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <map>
#include <set>
#include <unordered_map>

namespace proxgen::emit {
namespace {

bool identStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool identChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// A part function as printed: its name, parameter list and body lines.
struct Part {
  std::string name, params;
  std::vector<std::string> lines;
};

// One body's block in a part: the comment line before "  {", the lines inside.
struct Block {
  std::size_t part = 0, comment = 0, end = 0;  // comment: index of its comment line; end: of "  }"
};

// A subscript `[N]`, `[N + rest]` or anything else (loose: kept as printed).
struct Subscript {
  bool numeric = false;
  long lead = 0;
  std::string rest;  // " + j", " + 50 * j" after the leading integer
  std::string text;  // as printed, without the brackets
};

// The subscript as the kernel prints it: relative to `base` (the smallest
// leading index of the block), after `offset` (a matrix member's first
// column); as printed when the block's uses are loose.
std::string rebased(const Subscript& s, bool loose, long base, const std::string& offset = "") {
  if (loose) return "[" + s.text + "]";
  return fmt::format("[{}{}{}]", offset, s.lead - base, s.rest);
}

Subscript parseSubscript(const std::string& s) {
  Subscript r;
  r.text = s;
  std::size_t i = 0;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
  if (i == 0 || i > 9) return r;
  if (i == s.size() || s.compare(i, 3, " + ") == 0) {
    r.numeric = true;
    r.lead = std::stol(s.substr(0, i));
    r.rest = s.substr(i);
  }
  return r;
}

// Reads `[...][...]` at `at` (brackets do not nest in the printed code).
std::vector<std::string> readSubscripts(const std::string& line, std::size_t& at) {
  std::vector<std::string> out;
  while (at < line.size() && line[at] == '[') {
    const std::size_t close = line.find(']', at);
    if (close == std::string::npos) break;
    out.push_back(line.substr(at + 1, close - at - 1));
    at = close + 1;
  }
  return out;
}

// The length of a floating literal at `at` (digits with a '.' or an exponent,
// an optional 'f'), 0 if there is none; integers are not literals here.
std::size_t literalLength(const std::string& s, std::size_t at) {
  std::size_t i = at;
  bool point = false, exponent = false;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
  if (i == at) return 0;
  if (i < s.size() && s[i] == '.') {
    point = true;
    ++i;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
  }
  if (i < s.size() && s[i] == 'e') {
    std::size_t j = i + 1;
    if (j < s.size() && (s[j] == '-' || s[j] == '+')) ++j;
    const std::size_t digits = j;
    while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]))) ++j;
    if (j > digits) exponent = true, i = j;
  }
  if (!point && !exponent) return 0;
  if (i < s.size() && s[i] == 'f') ++i;
  if (i < s.size() && identChar(s[i])) return 0;
  return i - at;
}

// How a block uses a workspace member (a kernel parameter each).
struct MemberUse {
  std::string name;
  int cols = 0;            // > 0: a matrix member (rows x cols)
  bool array = false;      // false: a scalar
  bool loose = false;      // a subscript that is not N or N + ...: no rebasing
  long base = LONG_MAX;    // the smallest leading index of its last subscript
  bool written = false;    // stored or passed to a call (a scalar: by pointer; else by value)
};

// How a block uses an input or output array of its part (q, tau, M, ...).
struct PointerUse {
  bool loose = false;
  long base = LONG_MAX;
  bool written = false;
};

// A kernel parameter besides the table, and what the block passes for it.
struct Param {
  std::string before, name, after;  // the declaration: before + name + after
  std::string arg;                  // the call's argument
  bool lanewise = true;             // false for a part's scalar (mu: the same for every block)
  bool written = false;             // the block stores through it
  // The declaration with the name `name + lane`; in a paired kernel (lane
  // given) a pointer only read is not restrict: two blocks may read one array.
  std::string declaration(const std::string& lane = "") const {
    static const std::string restrict_ = "PROXGEN_RT_RESTRICT ";
    std::string b = before;
    if (!lane.empty() && !written && b.find(restrict_) != std::string::npos) b.erase(b.find(restrict_), restrict_.size());
    return b + name + lane + after;
  }
};

struct Canonical {
  std::string key;    // the kernel's text and parameter kinds
  std::string body;   // the kernel's body lines
  std::vector<std::string> constants;  // literal texts, signed
  std::vector<Param> params;           // besides the table
  // The elements it reads or stores: "w.v_x|3", "q|12", "w.KA_x|*" (a subscript
  // that is not a number: any element), for pairing blocks that do not overlap.
  std::set<std::string> touches, writes;
};

// The names a block may use besides its temporaries, members and parameters.
const std::set<std::string>& knownNames() {
  static const std::set<std::string> names{"Scalar", "const", "int", "for", "PROXGEN_RT_NO_UNROLL", "proxgen_rt",
                                           "std"};
  return names;
}

class Canonicalizer {
 public:
  Canonicalizer(const Part& part, const std::map<std::string, const Members::Member*>& members)
      : members_(members) {
    // "const Scalar* PROXGEN_RT_RESTRICT q, Scalar mu, Workspace& PROXGEN_RT_RESTRICT w"
    std::size_t at = 0;
    while (at < part.params.size()) {
      std::size_t comma = part.params.find(", ", at);
      if (comma == std::string::npos) comma = part.params.size();
      const std::string p = part.params.substr(at, comma - at);
      const std::size_t name = p.find_last_of(' ') + 1;
      const std::string n = p.substr(name), type = p.substr(0, name - 1);
      if (n == "w") {
      } else if (type.find('*') != std::string::npos) {
        pointers_[n] = type;
      } else {
        scalars_[n] = type;
      }
      at = comma + 2;
    }
  }

  // False when the block reads something the kernel could not (a part-level temporary).
  bool run(const std::vector<std::string>& lines, Canonical& out) {
    // Its temporaries (renamed x0, x1, ...) and loop variables (kept: the
    // loop heads are the ones tests/generated/structure.cpp admits).
    std::set<std::string> temps;
    for (const std::string& l : lines) {
      for (const char* decl : {"const Scalar ", "for (int "}) {
        const std::size_t d = l.find(decl);
        if (d == std::string::npos) continue;
        std::size_t i = d + std::string(decl).size(), j = i;
        while (j < l.size() && identChar(l[j])) ++j;
        (decl[0] == 'f' ? loopVars_ : temps).insert(l.substr(i, j - i));
      }
    }
    if (loopVars_.count("k")) return false;  // the table's name in the kernel
    // First pass: the members and pointers used, their smallest leading index.
    std::vector<std::string> code;
    for (const std::string& l : lines) {
      const std::size_t first = l.find_first_not_of(' ');
      if (first != std::string::npos && l.compare(first, 2, "//") == 0) continue;  // comments name one block
      if (l.find("//") != std::string::npos) return false;
      code.push_back(l);
    }
    for (const std::string& l : code)
      if (!scan(l, temps, nullptr)) return false;
    // Second pass: the text.
    std::string body;
    for (const std::string& l : code) {
      std::string o;
      if (!scan(l, temps, &o)) return false;
      body += (o.compare(0, 2, "  ") == 0 ? o.substr(2) : o) + "\n";  // the block's indent, less the braces'
    }
    std::string kinds;
    auto param = [&](const std::string& before, const std::string& name, const std::string& after,
                     const std::string& arg, bool lanewise, bool written) {
      out.params.push_back({before, name, after, arg, lanewise, written});
    };
    for (const auto& [n, u] : pointerUse_) {  // in name order: a deterministic signature
      const std::string& p = pointers_.at(n);
      param(p + " ", n, "", u.loose || u.base == 0 ? n : fmt::format("&{}[{}]", n, u.base), true, u.written);
      kinds += "p:" + n + p + (u.loose ? "L" : "") + ";";
    }
    for (const std::string& n : usedScalars_) {
      param(scalars_.at(n) + " ", n, "", n, false, false);
      kinds += "s:" + n + ";";
    }
    for (std::size_t i = 0; i < memberUse_.size(); ++i) {
      const MemberUse& u = memberUse_[i];
      const long base = u.loose || u.base == LONG_MAX ? 0 : u.base;
      const std::string p = paramName(i);
      if (!u.array && !u.written) {
        param("Scalar ", p, "", "w." + u.name, true, false);
        kinds += "v" + p + ";";
      } else if (!u.array) {
        param("Scalar* PROXGEN_RT_RESTRICT ", p, "", "&w." + u.name, true, true);
        kinds += "m" + p + ";";
      } else if (u.cols == 0) {
        param("Scalar* PROXGEN_RT_RESTRICT ", p, "", base == 0 ? "w." + u.name : fmt::format("&w.{}[{}]", u.name, base),
              true, u.written);
        kinds += "a" + p + ";";
      } else {
        param("Scalar (*PROXGEN_RT_RESTRICT ", p, fmt::format(")[{}]", u.cols), "w." + u.name, true, u.written);
        kinds += fmt::format("x{}{};", p, u.cols);
        if (!u.loose) {
          param("int ", p + "_col", "", fmt::format("{}", base), true, false);
          kinds += "o;";
        }
      }
    }
    out.body = std::move(body);
    out.constants = std::move(constants_);
    out.key = kinds + "\n" + out.body;
    out.touches = std::move(touches_);
    out.writes = std::move(writes_);
    return true;
  }

 private:
  // One line: checks it (o == nullptr: records the uses) or prints it into *o.
  bool scan(const std::string& l, const std::set<std::string>& temps, std::string* o) {
    std::size_t i = 0;
    while (i < l.size()) {
      const char c = l[i];
      if (identStart(c) && (i == 0 || (!identChar(l[i - 1]) && l[i - 1] != '.'))) {
        std::size_t j = i;
        while (j < l.size() && identChar(l[j])) ++j;
        const std::string id = l.substr(i, j - i);
        if (id == "w" && j < l.size() && l[j] == '.') {
          std::size_t e = j + 1;
          while (e < l.size() && identChar(l[e])) ++e;
          const std::string name = l.substr(j + 1, e - j - 1);
          std::vector<std::string> subs = readSubscripts(l, e);
          const bool stored = l.find_first_not_of(' ') == i && l.compare(e, 3, " = ") == 0;
          if (!member(name, subs, stored || insideCall(l, i), o)) return false;
          i = e;
          continue;
        }
        if (pointers_.count(id) && j < l.size() && l[j] == '[') {
          std::size_t e = j;
          std::vector<std::string> subs = readSubscripts(l, e);
          const bool stored = l.find_first_not_of(' ') == i && l.compare(e, 3, " = ") == 0;
          pointer(id, subs, stored || insideCall(l, i), o);
          i = e;
          continue;
        }
        const bool qualified = i >= 2 && l.compare(i - 2, 2, "::") == 0;
        const bool call = j < l.size() && l[j] == '(';
        if (temps.count(id)) {
          if (o) *o += tempName(id);
        } else if (scalars_.count(id)) {
          if (std::find(usedScalars_.begin(), usedScalars_.end(), id) == usedScalars_.end()) usedScalars_.push_back(id);
          if (o) *o += id;
        } else if (qualified || call || knownNames().count(id) || loopVars_.count(id)) {
          if (o) *o += id;
        } else {
          return false;  // a name the kernel would not have
        }
        i = j;
        continue;
      }
      if (std::isdigit(static_cast<unsigned char>(c)) && (i == 0 || !identChar(l[i - 1])) &&
          (i == 0 || l[i - 1] != '.')) {
        const std::size_t n = literalLength(l, i);
        if (n > 0) {
          if (o) {
            // A sign before the literal goes into the table: "a - 0.5*x" is
            // "a + k*x" with k = -0.5, the same value bit for bit.
            std::string sign;
            std::size_t back = o->find_last_not_of(' ');
            if (back != std::string::npos && ((*o)[back] == '-' || (*o)[back] == '+')) {
              sign = (*o)[back] == '-' ? "-" : "";
              o->erase(back);
              while (!o->empty() && o->back() == ' ') o->pop_back();
              const char before = o->empty() ? '(' : o->back();
              *o += (before == '(' || before == '=' || before == ',') ? " " : " + ";
            } else if (back != std::string::npos && (*o)[back] != '(' && (*o)[back] != '=' && (*o)[back] != ',' &&
                       (*o)[back] != '*' && (*o)[back] != '/') {
              return false;  // not a place the printer puts a literal
            }
            *o += fmt::format("k[{}]", constants_.size());
            constants_.push_back(sign + l.substr(i, n));
          }
          i += n;
          continue;
        }
        std::size_t j = i;
        while (j < l.size() && identChar(l[j])) ++j;
        if (o) *o += l.substr(i, j - i);
        i = j;
        continue;
      }
      if (o) *o += c;
      ++i;
    }
    return true;
  }

  // A member's parameter: its quantity's prefix (v, pA, IA: members.hpp) and
  // its place in the block ("v_m0" the first member read, ...).
  std::string paramName(std::size_t i) const {
    const std::string& n = memberUse_[i].name;
    const std::size_t u = n.find('_');
    return fmt::format("{}_m{}", u == std::string::npos ? n : n.substr(0, u), i);
  }

  std::string tempName(const std::string& id) {
    auto [it, inserted] = tempNames_.emplace(id, "");
    if (inserted) it->second = fmt::format("x{}", tempNames_.size() - 1);
    return it->second;
  }

  // Whether position `at` of `l` is inside a call's parentheses (`f(..., here)`).
  static bool insideCall(const std::string& l, std::size_t at) {
    int depth = 0;
    for (std::size_t i = at; i-- > 0;) {
      if (l[i] == ')') ++depth;
      if (l[i] == '(' && depth-- == 0) return i > 0 && identChar(l[i - 1]);
    }
    return false;
  }

  bool member(const std::string& name, const std::vector<std::string>& subs, bool written, std::string* o) {
    const auto m = members_.find(name);
    if (m == members_.end()) return false;
    const Members::Member& decl = *m->second;
    auto at = memberIndex_.find(name);
    if (at == memberIndex_.end()) {
      MemberUse u;
      u.name = name;
      u.array = decl.size > 0;
      u.cols = decl.columns;
      at = memberIndex_.emplace(name, memberUse_.size()).first;
      memberUse_.push_back(u);
    }
    MemberUse& u = memberUse_[at->second];
    if (u.array != !subs.empty() || (u.cols > 0 && subs.size() != 2) || (u.array && u.cols == 0 && subs.size() != 1))
      return false;
    if (!o) {
      record("w." + name, subs, written);
      u.written = u.written || written;
      if (!subs.empty()) {
        const Subscript s = parseSubscript(subs.back());
        if (!s.numeric) u.loose = true;
        else u.base = std::min(u.base, s.lead);
      }
      return true;
    }
    const std::string p = paramName(at->second);
    if (subs.empty()) {
      *o += u.written ? p + "[0]" : p;
      return true;
    }
    *o += p;
    for (std::size_t k = 0; k + 1 < subs.size(); ++k) *o += "[" + subs[k] + "]";
    *o += rebased(parseSubscript(subs.back()), u.loose, u.base, u.cols > 0 ? p + "_col + " : "");
    return true;
  }

  void pointer(const std::string& name, const std::vector<std::string>& subs, bool written, std::string* o) {
    PointerUse& u = pointerUse_[name];
    const Subscript s = parseSubscript(subs.empty() ? std::string() : subs.back());
    if (!o) {
      record(name, subs, written);
      u.written = u.written || written;
      if (subs.size() != 1 || !s.numeric) u.loose = true;
      else u.base = std::min(u.base, s.lead);
      return;
    }
    *o += name;
    for (std::size_t k = 0; k + 1 < subs.size(); ++k) *o += "[" + subs[k] + "]";
    *o += rebased(s, u.loose, u.base);
  }

  // One element the block reads or stores, for touches_ and writes_.
  void record(const std::string& name, const std::vector<std::string>& subs, bool written) {
    std::string key = name + "|";
    for (const std::string& sub : subs) {
      if (sub.empty() || sub.find_first_not_of("0123456789") != std::string::npos) {
        key = name + "|*";
        break;
      }
      key += sub + ",";
    }
    touches_.insert(key);
    if (written) writes_.insert(key);
  }

  const std::map<std::string, const Members::Member*>& members_;
  std::set<std::string> touches_, writes_;
  std::map<std::string, std::string> pointers_, scalars_;
  std::map<std::string, PointerUse> pointerUse_;
  std::vector<std::string> usedScalars_;
  std::vector<MemberUse> memberUse_;
  std::map<std::string, std::size_t> memberIndex_;
  std::map<std::string, std::string> tempNames_;
  std::set<std::string> loopVars_;
  std::vector<std::string> constants_;
};

std::vector<Part> splitParts(const std::string& text, std::string& unparsed) {
  std::vector<Part> parts;
  const std::string head = "PROXGEN_RT_NOINLINE void ";
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t eol = text.find('\n', at);
    const std::string line = text.substr(at, eol == std::string::npos ? std::string::npos : eol - at);
    at = eol == std::string::npos ? text.size() : eol + 1;
    if (line.rfind(head, 0) == 0) {
      Part p;
      const std::size_t open = line.find('(');
      const std::size_t close = line.rfind(") noexcept {");
      p.name = line.substr(head.size(), open - head.size());
      p.params = line.substr(open + 1, close - open - 1);
      parts.push_back(std::move(p));
      continue;
    }
    if (line == "}") {
      parts.back().lines.push_back("}");
      continue;
    }
    if (parts.empty()) {
      unparsed += line + "\n";
      continue;
    }
    parts.back().lines.push_back(line);
  }
  return parts;
}

// "eliminate body 20 'arm_left_5_link': ..." -> "arm_left_5_link"; a block
// that is not a body's ("multiplier update: ...") is named by its whole comment.
std::string blockBody(const std::string& comment) {
  const std::size_t a = comment.find('\'');
  const std::size_t b = a == std::string::npos ? a : comment.find('\'', a + 1);
  return b == std::string::npos ? comment : comment.substr(a + 1, b - a - 1);
}

// The kernel's text with the constants common to its blocks printed back as
// the literals they were (" + k[3]" with k[3] = -0.5 is " - 0.5", as the
// printer wrote it) and the others as k[slot].
std::string withCommonLiterals(const std::string& body, const std::vector<std::string>& constants,
                               const std::vector<char>& common, const std::vector<std::size_t>& slot) {
  std::string out;
  std::size_t i = 0;
  while (i < body.size()) {
    if (body.compare(i, 2, "k[") == 0 && (i == 0 || !identChar(body[i - 1]))) {
      const std::size_t close = body.find(']', i);
      const std::size_t c = std::stoul(body.substr(i + 2, close - i - 2));
      if (!common[c]) {
        out += fmt::format("k[{}]", slot[c]);
      } else if (out.size() >= 3 && out.compare(out.size() - 3, 3, " + ") == 0) {
        const std::string& v = constants[c];
        out.erase(out.size() - 3);
        out += v[0] == '-' ? " - " + v.substr(1) : " + " + v;
      } else {
        out += constants[c];
      }
      i = close + 1;
      continue;
    }
    out += body[i++];
  }
  return out;
}

// ---- Blocks in pairs: two blocks of one kernel, one after the other in a
// part and independent of each other, run as one call of the kernel's paired
// form, each value in a lane of proxgen_rt::lanes<Scalar, 2> (docs/emitter.md,
// "Blocks in pairs").

// Whether a name of its own starts at `i` (not a member `.x` or a qualified `::x`).
bool nameAt(const std::string& s, std::size_t i) {
  return identStart(s[i]) && (i == 0 || (!identChar(s[i - 1]) && s[i - 1] != '.' && s[i - 1] != ':'));
}

// `text` with each parameter of `lanewise` renamed to its lane's (v_m2 -> v_m2_a).
std::string inLane(const std::string& text, const std::set<std::string>& lanewise, const std::string& lane) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    if (nameAt(text, i)) {
      std::size_t j = i;
      while (j < text.size() && identChar(text[j])) ++j;
      const std::string id = text.substr(i, j - i);
      out += lanewise.count(id) ? id + lane : id;
      i = j;
      continue;
    }
    out += text[i++];
  }
  return out;
}

// A body's lines, without their line ends.
std::vector<std::string> linesOf(const std::string& body) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at < body.size();) {
    std::size_t eol = body.find('\n', at);
    if (eol == std::string::npos) eol = body.size();
    out.push_back(body.substr(at, eol - at));
    at = eol + 1;
  }
  return out;
}

class Pairer {
 public:
  Pairer(const std::set<std::string>& lanewise, bool table) : lanewise_(lanewise), table_(table) {}

  // The paired body, or false when a line has a form this does not know.
  bool run(const std::string& body, std::string& out) {
    for (const std::string& l : linesOf(body)) {
      const std::size_t first = l.find_first_not_of(' ');
      if (first == std::string::npos) continue;
      const std::string indent = l.substr(0, first), t = l.substr(first);
      if (t == "}" || t.rfind("PROXGEN_RT_NO_UNROLL for (", 0) == 0 || t.rfind("for (", 0) == 0) {
        if (inLane(t, lanewise_, "_a") != t) return false;  // a loop's bounds are the same for both
        out += l + "\n";
        continue;
      }
      if (t.back() != ';') return false;
      const std::string stmt = t.substr(0, t.size() - 1);
      const std::string decl = "const Scalar ";
      if (stmt.rfind(decl, 0) == 0) {  // a temporary: a pair
        const std::size_t eq = stmt.find(" = ");
        std::string value;
        if (eq == std::string::npos || !expression(stmt.substr(eq + 3), value)) return false;
        out += indent + "const ScalarPair " + stmt.substr(decl.size(), eq - decl.size()) + " = " + value + ";\n";
        continue;
      }
      std::size_t j = 0;
      while (j < stmt.size() && (identChar(stmt[j]) || stmt[j] == ':')) ++j;
      const std::string head = stmt.substr(0, j);
      if (j < stmt.size() && stmt[j] == '(' && stmt.back() == ')') {  // a call (sincos_joint_called): once per lane
        if (stmt.find("k[") != std::string::npos) return false;
        for (std::size_t x = stmt.find('x'); x != std::string::npos; x = stmt.find('x', x + 1))
          if ((x == 0 || !identChar(stmt[x - 1])) && x + 1 < stmt.size() && std::isdigit(static_cast<unsigned char>(stmt[x + 1])))
            return false;  // a temporary: a pair, not a lane's scalar
        out += indent + inLane(stmt, lanewise_, "_a") + ";\n" + indent + inLane(stmt, lanewise_, "_b") + ";\n";
        continue;
      }
      if (!lanewise_.count(head) || j >= stmt.size() || stmt[j] != '[') return false;
      std::size_t e = j;
      const std::vector<std::string> subs = readSubscripts(stmt, e);
      if (stmt.compare(e, 3, " = ") != 0) return false;
      std::string value;
      if (!expression(stmt.substr(e + 3), value)) return false;
      const std::string target = stmt.substr(0, e);
      out += indent + "proxgen_rt::scatter2<Scalar>(" + value + ", " + inLane(target, lanewise_, "_a") + ", " +
             inLane(target, lanewise_, "_b") + ");\n";
    }
    return true;
  }

 private:
  // An expression with each lanewise value gathered into a pair, each
  // constant of the table read as the pair of the two blocks'.
  bool expression(const std::string& e, std::string& out) const {
    // A call inside an expression (std::sqrt(x), Scalar(1)): its argument
    // would be a pair, which the scalar function does not take.
    // (A signed pair's flip takes pairs: signedBody below.)
    static const std::string flip = "proxgen_rt::flip";
    for (std::size_t p = e.find('('); p != std::string::npos; p = e.find('(', p + 1))
      if (p > 0 && identChar(e[p - 1]) && !(p >= flip.size() && e.compare(p - flip.size(), flip.size(), flip) == 0))
        return false;
    std::size_t i = 0;
    while (i < e.size()) {
      const char c = e[i];
      if (nameAt(e, i)) {
        std::size_t j = i;
        while (j < e.size() && identChar(e[j])) ++j;
        const std::string id = e.substr(i, j - i);
        if (id == "k" && table_ && j < e.size() && e[j] == '[') {
          std::size_t end = j;
          const std::vector<std::string> subs = readSubscripts(e, end);
          out += "proxgen_rt::pair_at(k, " + subs.front() + ")";
          i = end;
          continue;
        }
        if (lanewise_.count(id)) {
          std::size_t end = j;
          readSubscripts(e, end);
          const std::string v = e.substr(i, end - i);
          out += "proxgen_rt::gather2(" + inLane(v, lanewise_, "_a") + ", " + inLane(v, lanewise_, "_b") + ")";
          i = end;
          continue;
        }
        out += id;
        i = j;
        continue;
      }
      out += c;
      ++i;
    }
    return true;
  }

  const std::set<std::string>& lanewise_;
  bool table_;
};

// ---- Signed pairs: two blocks whose canonical text is the same but for
// signs (a left and a right arm whose joints turn about negated axes) run as
// a pair, each sign where they differ a flip of one lane (docs/emitter.md,
// "Mirrored blocks: signed pairs").

// A body with its sign slots marked: each term's start (an expression's
// first term, the first after "(": kTermStart, its sign '-' where a unary
// minus stood) and each binary " + " / " - " (kBinary), outside subscripts.
constexpr char kTermStart = '\x01';
constexpr char kBinary = '\x02';
struct SignSlots {
  std::string text;   // the body, each slot a marker
  std::string signs;  // '+' or '-' per slot, in order
};

// One statement's expression into `out`; false for a form it does not know.
bool markExpression(const std::string& e, SignSlots& out) {
  int bracket = 0;
  bool termStart = true;
  for (std::size_t i = 0; i < e.size();) {
    const char c = e[i];
    if (c == kTermStart || c == kBinary) return false;
    if (c == '(' && i > 0 && identChar(e[i - 1])) return false;  // a call: its arguments are no terms here
    if (bracket == 0 && termStart) {
      termStart = false;
      out.text += kTermStart;
      if (c == '-') {
        out.signs += '-';
        ++i;
        continue;
      }
      out.signs += '+';
    }
    if (c == '[') ++bracket;
    if (c == ']') --bracket;
    if (bracket == 0 && (e.compare(i, 3, " + ") == 0 || e.compare(i, 3, " - ") == 0)) {
      out.text += std::string(" ") + kBinary + " ";
      out.signs += e[i + 1];
      i += 3;
      if (i < e.size() && (e[i] == '-' || e[i] == '+')) return false;
      continue;
    }
    out.text += c;
    if (bracket == 0 && c == '(') termStart = true;
    ++i;
  }
  return bracket == 0;
}

// The statements' expressions of a canonical body, marked; false when a
// statement has a form the marking does not know (the block is not paired so).
bool markSigns(const std::string& body, SignSlots& out) {
  for (const std::string& l : linesOf(body)) {
    const std::size_t first = l.find_first_not_of(' ');
    const std::size_t eq = l.find(" = ");
    const bool statement = first != std::string::npos && l.back() == ';' && eq != std::string::npos &&
                           l.compare(first, 4, "for ") != 0 && l.compare(first, 20, "PROXGEN_RT_NO_UNROLL") != 0;
    if (!statement) {
      if (l.find(kTermStart) != std::string::npos || l.find(kBinary) != std::string::npos) return false;
      out.text += l + "\n";
      continue;
    }
    out.text += l.substr(0, eq + 3);
    if (!markExpression(l.substr(eq + 3, l.size() - eq - 4), out)) return false;
    out.text += ";\n";
  }
  return true;
}

// The marked text printed back: `pattern` per slot, '+' or '-' (that sign, as
// the printer writes it) or 'v' (the two lanes differ: a flip by the pair of
// signs k[first + n] for the n-th such slot, around the slot's term).
std::string signedBody(const std::string& text, const std::string& pattern, std::size_t first) {
  std::string out;
  std::size_t slot = 0, varying = first;
  int depth = 0;
  std::vector<int> open;  // the depths of the flips not closed yet
  auto close = [&](int d) {
    while (!open.empty() && open.back() == d) out += ")", open.pop_back();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == kTermStart || c == kBinary) {
      const char sign = pattern[slot++];
      if (c == kBinary) {
        out.pop_back();  // the space before the marker
        close(depth);
        ++i;  // the space after it
        out += sign == '-' ? " - " : " + ";
      } else if (sign == '-') {
        out += "-";
      }
      if (sign == 'v') {
        out += fmt::format("proxgen_rt::flip(k[{}], ", varying++);
        open.push_back(depth);
      }
      continue;
    }
    if (c == '(') ++depth;
    if (c == ')') close(depth), --depth;
    if (c == ';' || c == '\n') close(depth);
    out += c;
  }
  return out;
}

// Whether two blocks' elements overlap: one stores what the other reads or stores.
bool overlap(const std::set<std::string>& writes, const std::set<std::string>& touches) {
  for (const std::string& w : writes) {
    const std::string name = w.substr(0, w.find('|') + 1);
    if (touches.count(w) || touches.count(name + "*")) return true;
    if (w == name + "*") {
      const auto it = touches.lower_bound(name);
      if (it != touches.end() && it->compare(0, name.size(), name) == 0) return true;
    }
  }
  return false;
}

// Two blocks that can run as a pair: the second right after the first in one
// part, neither touching what the other stores.
// A pointer stored through is restrict in the paired form, so the two blocks
// must pass two of them (the columns of one matrix, w.dtau_dq at 4 and at 5,
// would be one pointer twice: left as two calls).
bool independent(const Block& a, const Canonical& ca, const Block& b, const Canonical& cb) {
  if (a.part != b.part || b.comment != a.end + 1 || overlap(ca.writes, cb.touches) || overlap(cb.writes, ca.touches))
    return false;
  for (std::size_t i = 0; i < ca.params.size(); ++i)
    if (ca.params[i].written && ca.params[i].arg == cb.params[i].arg) return false;
  return true;
}

// The arguments of a paired kernel's call for blocks a and b: the table of
// pairs holding `values` (the two blocks' constants, then a signed pair's
// signs; `size` pairs, none: no table), printed into `tables` the first time
// those values come, then each parameter's two arguments (a part's scalar once).
std::string pairArguments(const std::string& kernel, const std::string& values, std::size_t size,
                          const std::vector<Param>& a, const std::vector<Param>& b,
                          std::map<std::string, std::string>& tableOf, std::string& tables) {
  std::string args;
  if (size > 0) {
    auto [t, fresh] = tableOf.emplace(values, fmt::format("{}_p{}", kernel, tableOf.size()));
    if (fresh)
      tables += fmt::format("alignas(2 * sizeof(Scalar)) constexpr Scalar {}[{}] = {{{}}};\n", t->second, 2 * size,
                            values);
    args = t->second;
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    args += (args.empty() ? "" : ", ") + a[i].arg;
    if (a[i].lanewise) args += ", " + b[i].arg;
  }
  return args;
}

// Two blocks' constants interleaved (a0, b0, a1, b1, ...): a table of pairs' values.
std::string pairedConstants(const Canonical& a, const Canonical& b) {
  std::string both;
  for (std::size_t c = 0; c < a.constants.size(); ++c)
    both += (c ? ", " : "") + a.constants[c] + ", " + b.constants[c];
  return both;
}

// The parameters a block's pair holds one value of each block in (a pair each).
std::set<std::string> lanewiseOf(const Canonical& c) {
  std::set<std::string> out;
  for (const Param& p : c.params)
    if (p.lanewise) out.insert(p.name);
  return out;
}

// A kernel's parameter list: the table of constants `k` when it has one, then
// each parameter, twice (name_a, name_b) in the paired form (`paired`) unless
// it is a part's scalar, passed once.
std::string parameterList(bool table, const std::vector<Param>& params, bool paired) {
  std::vector<std::string> out;
  if (table) out.push_back("const Scalar* PROXGEN_RT_RESTRICT k");
  for (const Param& p : params) {
    if (!paired || !p.lanewise) {
      out.push_back(p.declaration());
    } else {
      out.push_back(p.declaration("_a"));
      out.push_back(p.declaration("_b"));
    }
  }
  return fmt::format("{}", fmt::join(out, ", "));
}

}  // namespace

SharedParts shareBlocks(const std::string& text, const Members& ws,
                        const std::function<bool(const std::string&)>& eligible, bool pairs) {
  std::map<std::string, const Members::Member*> members;
  for (const Members::Member& m : ws.all()) members[m.name] = &m;
  std::string before;
  std::vector<Part> parts = splitParts(text, before);

  struct Found {
    Block where;
    Canonical canon;
  };
  std::vector<Found> found;
  std::unordered_map<std::string, std::vector<std::size_t>> groups;
  std::vector<std::string> order;  // keys in order of first appearance
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (!eligible(parts[p].name)) continue;
    const std::vector<std::string>& lines = parts[p].lines;
    for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
      if (lines[i].rfind("  // ", 0) != 0 || lines[i + 1] != "  {") continue;
      std::size_t end = i + 2;
      while (end < lines.size() && lines[end] != "  }") ++end;
      if (end == lines.size()) break;
      Canonicalizer c(parts[p], members);
      Found f;
      f.where = {p, i, end};
      if (c.run({lines.begin() + long(i) + 2, lines.begin() + long(end)}, f.canon)) {
        auto [it, inserted] = groups.emplace(f.canon.key, std::vector<std::size_t>{});
        if (inserted) order.push_back(f.canon.key);
        it->second.push_back(found.size());
        found.push_back(std::move(f));
      }
      i = end;
    }
  }

  SharedParts out;
  std::string kernels;
  // Per part, the replaced blocks: comment line index -> (end, call line).
  std::map<std::size_t, std::map<std::size_t, std::pair<std::size_t, std::string>>> calls;
  // A block's comment line without its "  // ".
  const auto commentOf = [&](const Found& f) { return parts[f.where.part].lines[f.where.comment].substr(5); };
  // Block f joins kernel k: its comment, and its body once in k.bodies.
  const auto addBlock = [&](SharedKernel& k, const Found& f) {
    k.blocks.push_back(commentOf(f));
    const std::string body = blockBody(k.blocks.back());
    if (std::find(k.bodies.begin(), k.bodies.end(), body) == k.bodies.end()) k.bodies.push_back(body);
  };
  // Blocks f and h, one after the other, as one call of k's paired form at f's place.
  const auto callPair = [&](const std::string& kernel, const Found& f, const Found& h, const std::string& args) {
    calls[f.where.part][f.where.comment] = {
        h.where.end, fmt::format("{}\n  {}_x2({});", parts[h.where.part].lines[h.where.comment], kernel, args)};
  };
  for (const std::string& key : order) {
    const std::vector<std::size_t>& g = groups.at(key);
    if (g.size() < 2) continue;
    SharedKernel k;
    k.name = fmt::format("shared_{}", out.kernels.size());
    const Canonical& first = found[g.front()].canon;
    // A constant that is the same in every block of the group stays a literal
    // of the kernel (1.0 in 1.0 / D, the 0.5 of a rotation's half angle); the
    // table holds the others, renumbered.
    const std::size_t nk = first.constants.size();
    std::vector<char> common(nk, 1);
    for (std::size_t c = 0; c < nk; ++c)
      for (std::size_t n : g) common[c] = common[c] && found[n].canon.constants[c] == first.constants[c];
    std::vector<std::size_t> slot(nk, 0);
    std::size_t varying = 0;
    for (std::size_t c = 0; c < nk; ++c)
      if (!common[c]) slot[c] = varying++;
    const std::string body = withCommonLiterals(first.body, first.constants, common, slot);
    std::string tables;
    std::map<std::string, std::string> tableOf;  // values -> table: blocks with the same constants share one
    std::vector<std::string> values(g.size());
    for (std::size_t n = 0; n < g.size(); ++n) {
      const Found& f = found[g[n]];
      addBlock(k, f);
      for (std::size_t c = 0; c < nk; ++c)
        if (!common[c]) values[n] += (values[n].empty() ? "" : ", ") + f.canon.constants[c];
    }
    // The paired form, when the kernel's lines are ones it knows.
    // Every constant of it in the table of pairs, common ones too (pair_at: an
    // aligned load the compiler folds into the operation; a literal would be
    // loaded and duplicated).
    std::string pairedText;
    const bool pairable = pairs && Pairer(lanewiseOf(first), nk > 0).run(first.body, pairedText);
    std::string pairTables;
    std::map<std::string, std::string> pairTableOf;
    bool single = false;
    for (std::size_t n = 0; n < g.size(); ++n) {
      const Found& f = found[g[n]];
      if (pairable && n + 1 < g.size() && independent(f.where, f.canon, found[g[n + 1]].where, found[g[n + 1]].canon)) {
        const Found& h = found[g[n + 1]];
        callPair(k.name, f, h,
                 pairArguments(k.name, pairedConstants(f.canon, h.canon), nk, f.canon.params, h.canon.params,
                               pairTableOf, pairTables));
        ++k.pairs;
        ++n;
        continue;
      }
      single = true;
      std::string args;
      if (varying > 0) {
        auto [t, fresh] = tableOf.emplace(values[n], fmt::format("{}_k{}", k.name, tableOf.size()));
        if (fresh) tables += fmt::format("constexpr Scalar {}[{}] = {{{}}};\n", t->second, varying, values[n]);
        args = t->second;
      }
      for (const Param& p : f.canon.params) args += (args.empty() ? "" : ", ") + p.arg;
      calls[f.where.part][f.where.comment] = {f.where.end, fmt::format("  {}({});", k.name, args)};
    }
    kernels += fmt::format("// {} blocks of the same code, each over its constants (k) and members: {}.\n// The first: {}\n",
                           g.size(), fmt::join(k.bodies, ", "), commentOf(found[g.front()]));
    if (single) {
      kernels += tables;
      kernels += fmt::format("PROXGEN_RT_NOINLINE void {}({}) noexcept {{\n{}}}\n\n", k.name,
                             parameterList(varying > 0, first.params, false), body);
    }
    if (k.pairs > 0) {
      kernels += fmt::format("// {}'s blocks two at a time, one in each lane of a ScalarPair:\n// {} pair{}.\n", k.name,
                             k.pairs, k.pairs > 1 ? "s" : "");
      kernels += pairTables;
      kernels += fmt::format("PROXGEN_RT_NOINLINE void {}_x2({}) noexcept {{\n{}}}\n\n", k.name,
                             parameterList(nk > 0, first.params, true), pairedText);
    }
    out.kernels.push_back(std::move(k));
  }
  // Signed pairs: of the blocks no kernel took, two one after the other whose
  // text is the same but for signs, and independent, run as one call of a
  // paired kernel that turns one lane's sign where the two differ.
  std::vector<std::size_t> alone;
  for (const std::string& key : order)
    if (pairs && groups.at(key).size() == 1) alone.push_back(groups.at(key).front());
  std::sort(alone.begin(), alone.end());  // found is in file order
  struct Signed {
    std::string key;  // the parameter kinds and the marked body; empty: not markable, no pair
    SignSlots slots;
  };
  std::vector<Signed> marked(alone.size());
  for (std::size_t m = 0; m < alone.size(); ++m) {
    const Canonical& c = found[alone[m]].canon;
    if (markSigns(c.body, marked[m].slots)) marked[m].key = c.key.substr(0, c.key.size() - c.body.size()) + marked[m].slots.text;
  }
  std::map<std::string, std::vector<std::size_t>> signedKernel;  // key + pattern -> the pairs' first blocks (in alone)
  std::vector<std::string> signedOrder;
  for (std::size_t n = 0; n + 1 < alone.size(); ++n) {
    const Found& f = found[alone[n]];
    const Found& h = found[alone[n + 1]];
    if (marked[n].key.empty() || marked[n].key != marked[n + 1].key || !independent(f.where, f.canon, h.where, h.canon))
      continue;
    std::string pattern;
    for (std::size_t i = 0; i < marked[n].slots.signs.size(); ++i) {
      const char a = marked[n].slots.signs[i], b = marked[n + 1].slots.signs[i];
      pattern += a == b ? a : 'v';
    }
    const std::string key = marked[n].key + "\n" + pattern;
    auto [it, fresh] = signedKernel.emplace(key, std::vector<std::size_t>{});
    if (fresh) signedOrder.push_back(key);
    it->second.push_back(n);
    ++n;  // the second block is taken
  }
  for (const std::string& key : signedOrder) {
    const std::vector<std::size_t>& firsts = signedKernel.at(key);
    const Canonical& first = found[alone[firsts.front()]].canon;
    const std::string pattern = key.substr(key.rfind('\n') + 1);
    const std::size_t nk = first.constants.size();
    const std::size_t nv = std::size_t(std::count(pattern.begin(), pattern.end(), 'v'));
    std::string pairedText;
    if (!Pairer(lanewiseOf(first), nk + nv > 0).run(signedBody(marked[firsts.front()].slots.text, pattern, nk), pairedText))
      continue;  // left inline
    SharedKernel k;
    k.name = fmt::format("shared_{}", out.kernels.size());
    k.signs = int(nv);
    std::string pairTables;
    std::map<std::string, std::string> pairTableOf;
    for (std::size_t n : firsts) {
      const Found& f = found[alone[n]];
      const Found& h = found[alone[n + 1]];
      addBlock(k, f);
      addBlock(k, h);
      std::string both = pairedConstants(f.canon, h.canon);
      for (std::size_t i = 0; i < pattern.size(); ++i)
        if (pattern[i] == 'v')
          both += fmt::format("{}{}, {}", both.empty() ? "" : ", ", marked[n].slots.signs[i] == '-' ? "-1" : "1",
                              marked[n + 1].slots.signs[i] == '-' ? "-1" : "1");
      callPair(k.name, f, h, pairArguments(k.name, both, nk + nv, f.canon.params, h.canon.params, pairTableOf, pairTables));
      ++k.pairs;
    }
    kernels += fmt::format(
        "// {} blocks of the same code but for {} sign{} (mirrored: turned in one lane), two at a time: {}.\n"
        "// The first: {}\n",
        2 * k.pairs, nv, nv == 1 ? "" : "s", fmt::join(k.bodies, ", "), commentOf(found[alone[firsts.front()]]));
    kernels += pairTables;
    kernels += fmt::format("PROXGEN_RT_NOINLINE void {}_x2({}) noexcept {{\n{}}}\n\n", k.name,
                           parameterList(nk + nv > 0, first.params, true), pairedText);
    out.kernels.push_back(std::move(k));
  }
  if (out.kernels.empty()) {
    out.parts = text;
    return out;
  }
  bool paired = false;
  for (const SharedKernel& k : out.kernels) paired = paired || k.pairs > 0;
  out.parts = before + (paired ? "// Two blocks at once (the kernels' _x2 forms): a value of each in the lanes of a pair.\n"
                                 "using ScalarPair = proxgen_rt::lanes<Scalar, 2>;\n\n"
                               : "") +
              kernels;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const Part& part = parts[p];
    out.parts += fmt::format("PROXGEN_RT_NOINLINE void {}({}) noexcept {{\n", part.name, part.params);
    const auto c = calls.find(p);
    for (std::size_t i = 0; i < part.lines.size(); ++i) {
      out.parts += part.lines[i] + "\n";
      if (c == calls.end()) continue;
      const auto at = c->second.find(i);
      if (at == c->second.end()) continue;
      out.parts += at->second.second + "\n";
      i = at->second.first;
    }
  }
  return out;
}

}  // namespace proxgen::emit
