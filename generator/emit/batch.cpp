#include "emit/batch.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "model/error.hpp"

namespace proxgen::emit {
namespace {

const char* const kBatchHeaderTemplate =
#include "../../templates/solver_batch.hpp.tpl"
    ;
const char* const kBatchSourceTemplate =
#include "../../templates/solver_batch.cpp.tpl"
    ;

// The batched files are cut from the scalar ones (templates/solver.*.tpl):
// each cut checks that its marks are where the templates put them, so a
// change of the templates fails here, at generation, not in a compile.
std::string::size_type find(const std::string& text, const std::string& mark, const char* what,
                            std::string::size_type from = 0) {
  const auto at = text.find(mark, from);
  if (at == std::string::npos) throw std::logic_error(fmt::format("batch: the scalar {} has no '{}'", what, mark));
  return at;
}

// Every occurrence of `from` in `text` replaced by `to`.
std::string replaceAll(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// The Workspace's member lines, re-indented into BatchWorkspace::Lanes, over lanes.
std::string laneMembers(const std::string& header) {
  const std::string open = "struct Workspace {\n";
  const auto begin = find(header, open, "header") + open.size();
  const auto end = find(header, "};\n", "header", begin);
  std::string out;
  std::string::size_type at = begin;
  while (at < end) {
    const auto eol = header.find('\n', at);
    const std::string line = header.substr(at, eol - at);
    if (line.rfind("  Scalar ", 0) != 0) throw std::logic_error("batch: a Workspace member is not a Scalar: " + line);
    out += "    BatchScalar " + line.substr(9) + "\n";
    at = eol + 1;
  }
  return out;
}

// What NAME.cpp's namespace holds after its version checks: the part functions
// (an anonymous namespace) and the entry points, over Scalar and Workspace.
// The one call that does not resolve by overloading, std::sqrt, becomes the
// runtime's lane-wise sqrt; any other std:: function would have no lane form.
std::string laneBody(const std::string& source, const std::string& name) {
  const std::string open = "\nnamespace {\n";
  const auto begin = find(source, open, "source") + open.size();
  const std::string close = "}  // namespace " + name + "\n";
  const auto end = source.rfind(close);
  if (end == std::string::npos || end < begin) throw std::logic_error("batch: the scalar source has no '" + close + "'");
  std::string body = replaceAll(source.substr(begin, end - begin), "std::sqrt(", "proxgen_rt::sqrt(");
  if (body.find("std::") != std::string::npos)
    throw std::logic_error("batch: the scalar source calls a std:: function without a lane form");
  return body;
}

}  // namespace

bool validBatchWidth(int width) { return width == 2 || width == 4 || width == 8 || width == 16; }

BatchFiles batchFiles(const SolverFiles& scalar, int width) {
  if (!validBatchWidth(width)) throw Error(fmt::format("--batch: {} lanes: the width is 2, 4, 8 or 16", width));
  const std::string& header = scalar.header;
  if (header.find("\nvoid constrained_aba(") == std::string::npos || header.find("\nvoid prox_pv(") == std::string::npos)
    throw Error("--batch: the batched solvers are constrained_aba and prox_pv: the function list must hold both");
  const std::string hpp = ".hpp";
  if (scalar.headerName.size() <= hpp.size() ||
      scalar.headerName.compare(scalar.headerName.size() - hpp.size(), hpp.size(), hpp) != 0)
    throw std::logic_error("batch: the scalar header is not NAME.hpp");
  const std::string name = scalar.headerName.substr(0, scalar.headerName.size() - hpp.size());

  // The scalar files' banner (inputs, hashes, operations per call: each lane
  // runs those), and what these files add.
  const std::string banner = scalar.source.substr(0, find(scalar.source, "\n#include \"", "source")) +
                             fmt::format("// Batched over {} lanes: the command above with --batch {} ({}.hpp and\n"
                                         "// {}.cpp are the same with and without it).\n",
                                         width, width, name, name);
  // nc = 0: a C++ array cannot be empty.
  const bool noRows = header.find("nc = 0;") != std::string::npos;
  BatchFiles out;
  out.headerName = name + "_batch.hpp";
  out.sourceName = name + "_batch.cpp";
  out.header = fmt::format(fmt::runtime(kBatchHeaderTemplate), fmt::arg("banner", banner), fmt::arg("name", name),
                           fmt::arg("width", width), fmt::arg("members", laneMembers(header)),
                           fmt::arg("rows", noRows ? "1" : "nc"),
                           fmt::arg("rows_note", noRows ? "  // no constraint rows: one unused entry" : ""));
  out.source = fmt::format(fmt::runtime(kBatchSourceTemplate), fmt::arg("banner", banner), fmt::arg("name", name),
                           fmt::arg("body", laneBody(scalar.source, name)));
  return out;
}

}  // namespace proxgen::emit
