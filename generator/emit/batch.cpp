#include "emit/batch.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <vector>

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
// sincos is inlined whatever the scalar code does (below).
std::string laneBody(const std::string& source, const std::string& name) {
  const std::string open = "\nnamespace {\n";
  const auto begin = find(source, open, "source") + open.size();
  const std::string close = "}  // namespace " + name + "\n";
  const auto end = source.rfind(close);
  if (end == std::string::npos || end < begin) throw std::logic_error("batch: the scalar source has no '" + close + "'");
  std::string body = replaceAll(source.substr(begin, end - begin), "std::sqrt(", "proxgen_rt::sqrt(");
  // The lane kernel of sincos stays inline where the scalar code calls it
  // (sincosCalled, pass_kinematics.cpp): Talos' prox_pv_many at W = 8 took
  // 1.02-1.04 of the time with the call (its pair of vectors comes back
  // through memory), docs/batch.md.
  // (sincos_run does nothing for lanes: each joint's call computes its own.)
  body = replaceAll(body, "proxgen_rt::sincos_joint_called(", "proxgen_rt::sincos_joint(");
  if (body.find("std::") != std::string::npos)
    throw std::logic_error("batch: the scalar source calls a std:: function without a lane form");
  return body;
}

// ---- The library functions over lanes (--functions; docs/batch.md) ----
// Each selected library function gets NAME_batch (W states lane-interleaved)
// and NAME_many (n states in the plain layout), as the two solvers do: the
// entry point loads its inputs into the BatchWorkspace's lanes, runs the lane
// form of the function (cut from the scalar source with the rest) and stores
// its output from BatchWorkspace::out. The table holds each function's
// parameters in the scalar function's order; the scalar header's declaration
// is checked against it at generation, so a change of a signature fails here.

// One parameter of a library function.
struct Param {
  enum Kind { In, Work, Config, Out, Active } kind;
  const char* name;      // the scalar parameter's name
  const char* size = "";  // In, Out: its number of values, in the header's constants
  const char* lanes = "";  // In: the BatchWorkspace member holding it in lanes
  bool nullable = false;  // In: may be nullptr, as the scalar function says
};

struct LibraryFunction {
  const char* name;
  std::vector<Param> params;
};

const std::vector<LibraryFunction>& libraryFunctions() {
  const Param q{Param::In, "q", "nq", "q"}, v{Param::In, "v", "nv", "v"}, work{Param::Work, "w"},
      active{Param::Active, "active"};
  static const std::vector<LibraryFunction> table{
      {"inverse_dynamics",
       {q, v, {Param::In, "qdd", "nv", "qdd"}, {Param::In, "lambda", "nc", "lambda", true}, work,
        {Param::Out, "tau", "nv"}, active}},
      {"nonlinear_effects", {q, v, work, {Param::Out, "h", "nv"}}},
      {"mass_matrix", {q, work, {Param::Out, "M", "nv * nv"}}},
      {"mass_matrix_inverse", {q, work, {Param::Out, "Minv", "nv * nv"}}},
      {"constraint_placements", {q, work, {Param::Out, "X", "12 * ncons"}}},
      {"constraint_jacobian", {q, work, {Param::Out, "J", "nc * nv"}, active}},
      {"constraint_drift", {q, v, work, {Param::Out, "gamma", "nc"}, active}},
      {"delassus", {q, work, {Param::Out, "G", "nc * nc"}, active}},
      {"delassus_inverse", {q, {Param::Config, "s"}, work, {Param::Out, "Ginv", "nc * nc"}}},
      {"constraint_wrenches", {q, {Param::In, "lambda", "nc", "lambda"}, work, {Param::Out, "W", "6 * ncons"}}},
      {"inverse_dynamics_derivatives",
       {q, v, {Param::In, "qdd", "nv", "qdd"}, {Param::In, "lambda", "nc", "lambda", true}, work,
        {Param::Out, "dtau_dq", "nv * nv"}, {Param::Out, "dtau_dv", "nv * nv"}}},
      {"forward_dynamics_derivatives",
       {q, v, {Param::In, "tau", "nv", "tau"}, work, {Param::Out, "qdd", "nv"}, {Param::Out, "dqdd_dq", "nv * nv"},
        {Param::Out, "dqdd_dv", "nv * nv"}, {Param::Out, "dqdd_dtau", "nv * nv"}}},
  };
  return table;
}

// The parameter as declared; `workspace` is Workspace or BatchWorkspace.
std::string declared(const Param& p, const char* workspace) {
  switch (p.kind) {
    case Param::In: return fmt::format("const Scalar* {}", p.name);
    case Param::Work: return fmt::format("{}& {}", workspace, p.name);
    case Param::Config: return fmt::format("const Settings& {}", p.name);
    case Param::Out: return fmt::format("Scalar* {}", p.name);
    case Param::Active: return fmt::format("const bool* {} = all_active", p.name);
  }
  throw std::logic_error("batch: a parameter kind");
}

// `head(a, b, ...) noexcept`, the arguments wrapped under the parenthesis past 110 columns.
std::string wrapped(const std::string& head, const std::vector<std::string>& args, const std::string& tail) {
  std::string out = head + "(";
  std::string::size_type lineStart = 0;
  const std::string indent(head.size() + 1, ' ');
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string piece = args[i] + (i + 1 < args.size() ? "," : ")" + tail);
    if (i > 0) {
      if (out.size() - lineStart + 1 + piece.size() > 110) {
        out += "\n";
        lineStart = out.size();
        out += indent;
      } else {
        out += " ";
      }
    }
    out += piece;
  }
  return out;
}

// Whitespace runs as one space: declarations compared whatever their wrapping.
std::string squeezed(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool space = c == ' ' || c == '\n';
    if (space && (out.empty() || out.back() == ' ')) continue;
    out += space ? ' ' : c;
  }
  return out;
}

// The library functions the scalar header declares, each checked against the table.
std::vector<const LibraryFunction*> heldFunctions(const std::string& header) {
  std::vector<const LibraryFunction*> out;
  for (const LibraryFunction& f : libraryFunctions()) {
    const auto at = header.find(fmt::format("\nvoid {}(", f.name));
    if (at == std::string::npos) continue;
    const auto end = find(header, ") noexcept;", "header", at);
    std::vector<std::string> args;
    for (const Param& p : f.params) args.push_back(declared(p, "Workspace"));
    const std::string expected = squeezed(wrapped(fmt::format("void {}", f.name), args, " noexcept;"));
    const std::string actual = squeezed(header.substr(at + 1, end + 11 - (at + 1)));
    if (actual != expected)
      throw std::logic_error(fmt::format("batch: the scalar {} is not '{}' but '{}'", f.name, expected, actual));
    out.push_back(&f);
  }
  return out;
}

// The header's part: the size of BatchWorkspace::out and the declarations.
std::string libraryDeclarations(const std::vector<const LibraryFunction*>& held) {
  std::string out =
      "\n// The library functions over lanes (generate --functions): NAME_batch and\n"
      "// NAME_many are NAME (the scalar function of the solver's header) on\n"
      "// batch_width states lane-interleaved and on n states in the plain layout, as\n"
      "// the solvers' _batch and _many: inputs and outputs as the solvers' arrays\n"
      "// (element i of state l at [i * batch_width + l], a matrix's element i its\n"
      "// row-major index: M[r * nv + c] of state l at [(r * nv + c) * batch_width + l];\n"
      "// _many: state k's at + k * size, its last batch's unused lanes dropped).\n"
      "// `active` and the Settings are shared by the states. What the scalar\n"
      "// function says holds lane by lane; each lane's answer is its answer.\n";
  for (const LibraryFunction* f : held) {
    std::vector<std::string> args;
    for (const Param& p : f->params) args.push_back(declared(p, "BatchWorkspace"));
    out += wrapped(fmt::format("void {}_batch", f->name), args, " noexcept;") + "\n";
    args.insert(args.begin(), "int n");
    out += wrapped(fmt::format("void {}_many", f->name), args, " noexcept;") + "\n";
  }
  return out;
}

// The outputs of one function, one after another in BatchWorkspace::out: the
// offset of each (a sum of the earlier sizes, "" for the first) and the total.
std::vector<std::string> outOffsets(const LibraryFunction& f, std::string* total = nullptr) {
  std::vector<std::string> offsets;
  std::string sum;
  for (const Param& p : f.params) {
    if (p.kind != Param::Out) continue;
    offsets.push_back(sum);
    sum += (sum.empty() ? "" : " + ") + fmt::format("({})", p.size);
  }
  if (total) *total = sum;
  return offsets;
}

// BatchWorkspace::out: as large as the largest sum of one held function's
// outputs (at least 1: a C++ array cannot be empty), and its size's function.
std::string outSizeFunction(const std::vector<const LibraryFunction*>& held) {
  std::vector<std::string> sizes;
  for (const LibraryFunction* f : held) {
    std::string total;
    outOffsets(*f, &total);
    if (std::find(sizes.begin(), sizes.end(), total) == sizes.end()) sizes.push_back(total);
  }
  std::string out =
      "\n// The largest output of the library functions below (BatchWorkspace::out).\n"
      "constexpr int batch_out_size() noexcept {\n"
      "  int size = 1;\n";
  for (const std::string& size : sizes) out += fmt::format("  if ({0} > size) size = {0};\n", size);
  return out + "  return size;\n}\n";
}
const char* const kOutMember = "  BatchScalar out[batch_out_size()];  // the library functions' outputs in lanes\n";

// The source's part: the lane copies and each function's two entry points.
std::string libraryDefinitions(const std::vector<const LibraryFunction*>& held) {
  std::string out =
      "\n// The library functions' entry points: their inputs into lanes, the lane\n"
      "// function, its output out of lanes.\n"
      "namespace {\n\n"
      "// size values of each of the batch_width states, lane-interleaved, into lanes, and back.\n"
      "void loadLanes(const Scalar* x, int size, BatchScalar* lanes) noexcept {\n"
      "  for (int i = 0; i < size; ++i) lanes[i] = BatchScalar::load(x + i * batch_width);\n"
      "}\n"
      "void storeLanes(const BatchScalar* lanes, int size, Scalar* x) noexcept {\n"
      "  for (int i = 0; i < size; ++i) lanes[i].store(x + i * batch_width);\n"
      "}\n\n"
      "// States first .. first + used - 1 of the plain layout (size values each)\n"
      "// into lanes, the unused lanes repeating state first; and the used lanes back.\n"
      "void gatherLanes(const Scalar* x, int size, int first, int used, BatchScalar* lanes) noexcept {\n"
      "  for (int l = 0; l < batch_width; ++l) {\n"
      "    const std::size_t k = std::size_t(first + (l < used ? l : 0));\n"
      "    for (int i = 0; i < size; ++i) lanes[i].set(l, x[k * std::size_t(size) + std::size_t(i)]);\n"
      "  }\n"
      "}\n"
      "void scatterLanes(const BatchScalar* lanes, int size, int first, int used, Scalar* x) noexcept {\n"
      "  for (int l = 0; l < used; ++l) {\n"
      "    const std::size_t k = std::size_t(first + l);\n"
      "    for (int i = 0; i < size; ++i) x[k * std::size_t(size) + std::size_t(i)] = lanes[i][l];\n"
      "  }\n"
      "}\n\n"
      "}  // namespace\n";
  for (const LibraryFunction* f : held) {
    std::vector<std::string> args, call;
    std::string load, gather, store, scatter;
    const std::vector<std::string> offsets = outOffsets(*f);
    std::size_t outs = 0;
    for (const Param& p : f->params) {
      args.push_back(declared(p, "BatchWorkspace"));
      if (p.kind == Param::Active) args.back() = fmt::format("const bool* {}", p.name);  // (the default is the header's)
      switch (p.kind) {
        case Param::In: {
          const std::string guard = p.nullable ? fmt::format("if ({}) ", p.name) : "";
          load += fmt::format("  {}loadLanes({}, {}, w.{});\n", guard, p.name, p.size, p.lanes);
          gather += fmt::format("    {}gatherLanes({}, {}, first, used, w.{});\n", guard, p.name, p.size, p.lanes);
          call.push_back(p.nullable ? fmt::format("{} ? w.{} : nullptr", p.name, p.lanes) : fmt::format("w.{}", p.lanes));
          break;
        }
        case Param::Work: call.push_back("w.w"); break;
        case Param::Config: call.push_back(fmt::format("laneSettings({}, w)", p.name)); break;
        case Param::Out: {
          // Several outputs (the derivatives) lie one after another in w.out.
          const std::string& offset = offsets[outs++];
          const std::string lanes = offset.empty() ? "w.out" : fmt::format("w.out + {}", offset);
          store += fmt::format("  storeLanes({}, {}, {});\n", lanes, p.size, p.name);
          scatter += fmt::format("    scatterLanes({}, {}, first, used, {});\n", lanes, p.size, p.name);
          call.push_back(lanes);
          break;
        }
        case Param::Active: call.push_back(p.name); break;
      }
    }
    std::string joined;
    for (const std::string& c : call) joined += (joined.empty() ? "" : ", ") + c;
    const std::string run = fmt::format("batch_lanes::{}({});\n", f->name, joined);
    out += "\n" + wrapped(fmt::format("void {}_batch", f->name), args, " noexcept {") + "\n" + load + "  " + run +
           store + "}\n";
    args.insert(args.begin(), "int n");
    out += "\n" + wrapped(fmt::format("void {}_many", f->name), args, " noexcept {") + "\n" +
           "  for (int first = 0; first < n; first += batch_width) {\n"
           "    const int used = n - first < batch_width ? n - first : batch_width;\n" +
           gather + "    " + run + scatter + "  }\n}\n";
  }
  return out;
}

}  // namespace

bool validBatchWidth(int width) { return width == 2 || width == 4 || width == 8 || width == 16; }

int parseBatchWidth(const std::string& text, bool given) {
  if (!given) return 0;
  for (const char* valid : {"2", "4", "8", "16"})
    if (text == valid) return std::atoi(valid);
  fail("command line", "--batch", fmt::format("the lane width W is 2, 4, 8 or 16, got {}", quoted(text)));
}

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
  const std::string& unshared = scalar.unsharedSource.empty() ? scalar.source : scalar.unsharedSource;
  const std::string banner = unshared.substr(0, find(unshared, "\n#include \"", "source")) +
                             fmt::format("// Batched over {} lanes: the command above with --batch {} ({}.hpp and\n"
                                         "// {}.cpp are the same with and without it).\n",
                                         width, width, name, name);
  // nc = 0: a C++ array cannot be empty.
  const bool noRows = header.find("nc = 0;") != std::string::npos;
  BatchFiles out;
  out.headerName = name + "_batch.hpp";
  out.sourceName = name + "_batch.cpp";
  // The library functions the solver holds: none gives the files of the two solvers alone.
  const std::vector<const LibraryFunction*> held = heldFunctions(header);
  out.header = fmt::format(fmt::runtime(kBatchHeaderTemplate), fmt::arg("banner", banner), fmt::arg("name", name),
                           fmt::arg("width", width), fmt::arg("members", laneMembers(header)),
                           fmt::arg("rows", noRows ? "1" : "nc"),
                           fmt::arg("rows_note", noRows ? "  // no constraint rows: one unused entry" : ""),
                           fmt::arg("out_size", held.empty() ? "" : outSizeFunction(held)),
                           fmt::arg("out_members", held.empty() ? "" : kOutMember),
                           fmt::arg("library", held.empty() ? "" : libraryDeclarations(held)));
  out.source = fmt::format(fmt::runtime(kBatchSourceTemplate), fmt::arg("banner", banner), fmt::arg("name", name),
                           fmt::arg("body", laneBody(unshared, name)),
                           fmt::arg("library", held.empty() ? "" : libraryDefinitions(held)));
  return out;
}

}  // namespace proxgen::emit
