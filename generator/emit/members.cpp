#include "emit/members.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace proxgen::emit {

std::string Members::member(const std::string& base, int size, int idx, const std::string& comment) {
  auto it = index_.find(base);
  if (it == index_.end()) {
    index_[base] = int(members_.size());
    members_.push_back({base, size, comment});
  } else if (members_[std::size_t(it->second)].size != size) {
    throw std::logic_error("emitter: member " + base + " used with two sizes");
  }
  return size == 0 ? "w." + base : fmt::format("w.{}[{}]", base, idx);
}

std::string Members::member(const std::string& base, int rows, int cols, int r, int c, const std::string& comment) {
  member(base, rows * cols, 0, comment);
  Member& m = members_[std::size_t(index_[base])];
  if (m.columns != 0 && m.columns != cols) throw std::logic_error("emitter: member " + base + " used with two shapes");
  m.columns = cols;
  return fmt::format("w.{}[{}][{}]", base, r, c);
}

std::string Members::loopSlot(const std::string& base, int rows, int cols, int r, int c, const std::string& comment) {
  member(base, rows, cols, r, c, comment);
  return c == 0 ? fmt::format("w.{}[{}][j]", base, r) : fmt::format("w.{}[{}][{} + j]", base, r, c);
}

std::string Members::loopSlot(const std::string& base, int size, int idx, const std::string& comment) {
  const std::string first = member(base, size, idx, comment);  // declares the member
  return idx == 0 ? first.substr(0, first.size() - 2) + "j]" : first.substr(0, first.size() - 1) + " + j]";
}

int Members::scalars() const {
  int n = 0;
  for (const Member& m : members_) n += m.size == 0 ? 1 : m.size;
  return n;
}

std::string Members::declarations() const {
  std::string out;
  for (const Member& mb : members_) {
    const std::string decl = mb.size == 0      ? fmt::format("Scalar {};", mb.name)
                             : mb.columns > 0 ? fmt::format("Scalar {}[{}][{}];", mb.name, mb.size / mb.columns, mb.columns)
                                              : fmt::format("Scalar {}[{}];", mb.name, mb.size);
    out += fmt::format("  {:<28} // {}\n", decl, mb.comment);
  }
  return out;
}

}  // namespace proxgen::emit
