// Issue 19 item 8: `--name j1` (or log, gamma, size_t, M_PI_2, a URDF named
// sin.urdf) gave a namespace that collides with a global name or a macro of
// the C and C++ libraries, and code that does not compile, with exit 0.
//
// Two checks, both with GCC (the compiler the list was derived with; tests/CMakeLists.txt):
//  - the list is complete for this platform: every identifier of the standard
//    and POSIX headers that cannot be a namespace at global scope (the
//    compiler says which), every macro they define (-dM) and every existing
//    namespace is reserved, hence mangled by sanitizeIdentifier;
//  - names of every kind (the issue's, macros, types, functions, objects, the
//    runtime's own) given as --name or as the URDF's file name generate code
//    that compiles and links, all in one program that includes every standard
//    header before the generated ones, with the options of every compile of
//    generated code (proxgen_solver_compile_options ... CHECKED).
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "emit/identifiers.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

namespace fs = std::filesystem;
using test::ProcessResult;

std::string good(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/" + file; }

// The headers a translation unit that includes a generated solver may have
// included before it: the whole C++17 library, the C headers, and the POSIX
// headers of a typical program.
const char* const kHeaders[] = {
    "algorithm", "any", "array", "atomic", "bitset", "cassert", "cctype", "cerrno", "cfenv", "cfloat", "charconv",
    "chrono", "cinttypes", "climits", "clocale", "cmath", "complex", "condition_variable", "csetjmp", "csignal",
    "cstdarg", "cstddef", "cstdint", "cstdio", "cstdlib", "cstring", "ctime", "cuchar", "cwchar", "cwctype", "deque",
    "exception", "execution", "filesystem", "forward_list", "fstream", "functional", "future", "initializer_list",
    "iomanip", "ios", "iosfwd", "iostream", "istream", "iterator", "limits", "list", "locale", "map", "memory",
    "memory_resource", "mutex", "new", "numeric", "optional", "ostream", "queue", "random", "ratio", "regex",
    "scoped_allocator", "set", "shared_mutex", "sstream", "stack", "stdexcept", "streambuf", "string", "string_view",
    "system_error", "thread", "tuple", "type_traits", "typeindex", "typeinfo", "unordered_map", "unordered_set",
    "utility", "valarray", "variant", "vector", "assert.h", "complex.h", "ctype.h", "errno.h", "fenv.h", "float.h",
    "inttypes.h", "iso646.h", "limits.h", "locale.h", "math.h", "setjmp.h", "signal.h", "stdarg.h", "stdbool.h",
    "stddef.h", "stdint.h", "stdio.h", "stdlib.h", "string.h", "time.h", "uchar.h", "wchar.h", "wctype.h", "fcntl.h",
    "pthread.h", "sys/stat.h", "sys/types.h", "unistd.h"};

// C++ keywords: a namespace of one is a syntax error that derails the parse of
// what follows, so the probe leaves them out (the unit tests cover them).
const std::set<std::string> kKeywords = {
    "alignas", "alignof", "and", "and_eq", "asm", "auto", "bitand", "bitor", "bool", "break", "case", "catch", "char",
    "char8_t", "char16_t", "char32_t", "class", "compl", "concept", "const", "consteval", "constexpr", "constinit",
    "const_cast", "continue", "co_await", "co_return", "co_yield", "decltype", "default", "delete", "do", "double",
    "dynamic_cast", "else", "enum", "explicit", "export", "extern", "false", "float", "for", "friend", "goto", "if",
    "inline", "int", "long", "mutable", "namespace", "new", "noexcept", "not", "not_eq", "nullptr", "operator", "or",
    "or_eq", "private", "protected", "public", "register", "reinterpret_cast", "requires", "return", "short", "signed",
    "sizeof", "static", "static_assert", "static_cast", "struct", "switch", "template", "this", "thread_local",
    "throw", "true", "try", "typedef", "typeid", "typename", "union", "unsigned", "using", "virtual", "void",
    "volatile", "wchar_t", "while", "xor", "xor_eq"};

class Scratch {
 public:
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "proxgen_test_reserved_XXXXXX").string();
    EXPECT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path operator/(const std::string& f) const { return dir_ / f; }

 private:
  fs::path dir_;
};

std::string compiler() { return PROXGEN_CXX_COMPILER; }

std::vector<std::string> checkedOptions() {
  std::vector<std::string> out;
  std::istringstream in(PROXGEN_SOLVER_COMPILE_OPTIONS);
  for (std::string o; in >> o;) out.push_back(o);
  return out;
}

std::string allHeaders() {
  std::string out;
  for (const char* h : kHeaders) out += std::string("#include <") + h + ">\n";
  return out;
}

// Lines "FILE:LINE:..." of `log` for FILE = probe: the probe lines the compiler objected to.
std::set<int> probeLines(const std::string& log) {
  std::set<int> out;
  const std::regex line("^probe:([0-9]+):");
  std::istringstream in(log);
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (std::regex_search(l, m, line)) out.insert(std::stoi(m[1]));
  }
  return out;
}

TEST(ReservedNames, EveryGlobalNameAndMacroOfTheLibrariesIsReserved) {
  Scratch s;
  std::ofstream(s / "headers.hpp") << allHeaders();
  // Macros (object- and function-like): reserved whatever follows the name.
  ProcessResult r = test::runProgram(compiler(), {"-std=c++17", "-dM", "-E", (s / "headers.hpp").string()});
  ASSERT_EQ(r.code, 0) << r.err;
  std::set<std::string> macros;
  {
    std::istringstream in(r.out);
    const std::regex def("^#define ([A-Za-z][A-Za-z0-9_]*)");
    for (std::string l; std::getline(in, l);) {
      std::smatch m;
      // The sanitiser never produces "__" or a trailing "_".
      if (std::regex_search(l, m, def) && m[1].str().find("__") == std::string::npos && m[1].str().back() != '_')
        macros.insert(m[1]);
    }
  }
  ASSERT_GT(macros.size(), 500u);  // the probe saw the headers
  // Every identifier of the preprocessed headers is a candidate: the compiler
  // rejects `namespace X {}` for each that names a function, object or type at
  // global scope, and accepts `namespace P { using namespace X; }` for each
  // that is a namespace already (a solver there would reopen it).
  r = test::runProgram(compiler(), {"-std=c++17", "-E", "-P", (s / "headers.hpp").string()});
  ASSERT_EQ(r.code, 0) << r.err;
  std::set<std::string> tokens;
  {
    const std::regex id("[A-Za-z][A-Za-z0-9_]*");
    for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), id); it != std::sregex_iterator(); ++it) {
      const std::string t = it->str();
      // The sanitiser never produces "__" or a trailing "_", nor a keyword (unit-tested).
      if (t.find("__") == std::string::npos && t.back() != '_' && !kKeywords.count(t) && !macros.count(t)) tokens.insert(t);
    }
  }
  ASSERT_GT(tokens.size(), 1000u);
  const std::vector<std::string> list(tokens.begin(), tokens.end());
  std::string asNamespace = "#include \"headers.hpp\"\n", asUsing = asNamespace;
  for (std::size_t k = 0; k < list.size(); ++k) {
    asNamespace += "#line " + std::to_string(k + 1) + " \"probe\"\nnamespace " + list[k] + " {}\n";
    asUsing += "#line " + std::to_string(k + 1) + " \"probe\"\nnamespace probe_" + std::to_string(k) +
               " { using namespace " + list[k] + "; }\n";
  }
  std::ofstream(s / "as_namespace.cpp") << asNamespace;
  std::ofstream(s / "as_using.cpp") << asUsing;
  const ProcessResult ns = test::runProgram(compiler(), {"-std=c++17", "-fsyntax-only", "-fmax-errors=0", "-I",
                                                         (s / "").string(), (s / "as_namespace.cpp").string()});
  const ProcessResult us = test::runProgram(compiler(), {"-std=c++17", "-fsyntax-only", "-fmax-errors=0", "-I",
                                                         (s / "").string(), (s / "as_using.cpp").string()});
  const std::set<int> collide = probeLines(ns.err), notNamespaces = probeLines(us.err);
  // The probes ran to the end (a derailed parse would blame every later line).
  ASSERT_LT(collide.size(), list.size() / 2) << ns.err.substr(0, 2000);
  ASSERT_GT(collide.size(), 500u) << ns.err.substr(0, 2000);
  std::vector<std::string> missing;
  const auto check = [&](const std::string& name) {
    if (!emit::isReservedIdentifier(name) || emit::sanitizeIdentifier(name) == name) missing.push_back(name);
  };
  for (const std::string& m : macros) check(m);
  for (int line : collide) check(list[std::size_t(line - 1)]);
  for (std::size_t k = 0; k < list.size(); ++k)
    if (!notNamespaces.count(int(k + 1))) check(list[k]);  // `std`
  EXPECT_TRUE(missing.empty()) << missing.size() << " names of the libraries are not reserved, e.g. "
                               << (missing.empty() ? "" : missing.front());
  for (std::size_t k = 0; k < missing.size() && k < 40; ++k) ADD_FAILURE() << "not reserved: " << missing[k];
}

// Names of every kind, as --name and as the URDF's file name, generate code
// that compiles and links in one program after every standard header.
TEST(ReservedNames, SolversNamedAfterLibraryNamesCompile) {
  Scratch s;
  const std::vector<std::string> names = {
      // the issue's, then a macro, a function-like macro, types, a struct tag,
      // functions, objects, the namespace std, and the runtime's and files' own
      "j1", "log", "gamma", "size_t", "M_PI_2", "NAN", "isnan", "FILE", "tm", "stat", "errno", "stdin", "EDOM",
      "INT8_MAX", "std", "proxgen_rt", "Scalar", "main"};
  std::string program = allHeaders();
  std::vector<std::string> sources;
  int index = 0;
  const auto generate = [&](const std::vector<std::string>& args, const std::string& expectedName) {
    const fs::path out = s / ("out" + std::to_string(index++));
    std::vector<std::string> all = args;
    all.insert(all.end(), {"--out", out.string()});
    const ProcessResult r = test::runProgram(PROXGEN_BINARY_PATH, all);
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(fs::exists(out / (expectedName + ".hpp"))) << "expected " << expectedName << ": " << r.out;
    program += "#include \"" + (out / (expectedName + ".hpp")).string() + "\"\n";
    sources.push_back((out / (expectedName + ".cpp")).string());
  };
  std::string calls;
  for (const std::string& n : names) {
    const std::string id = emit::sanitizeIdentifier(n);
    EXPECT_EQ(id, "kw_" + n) << "not reserved: " << n;
    generate({"generate", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--name", n}, id);
    calls += "  { static " + id + "::Workspace w; " + id + "::Settings st; " + id + "::Scalar q[" + id + "::nq] = {}, v[" +
             id + "::nv] = {}, tau[" + id + "::nv] = {}, qdd[" + id + "::nv], l[" + id + "::nc]; " + id +
             "::prox_pv(q, v, tau, st, w, qdd, l); ok = ok && qdd[0] == qdd[0]; }\n";
  }
  // The URDF's file name as the default name: sin.urdf.
  std::filesystem::copy_file(good("arm3.urdf"), s / "sin.urdf");
  generate({"generate", (s / "sin.urdf").string(), "--layout", good("arm3_tool.yaml")}, "kw_sin");
  program += "int main() {\n  bool ok = true;\n" + calls + "  return ok ? 0 : 1;\n}\n";
  std::ofstream(s / "main.cpp") << program;
  std::vector<std::string> args = {"-std=c++17"};
  for (const std::string& o : checkedOptions()) args.push_back(o);
  args.insert(args.end(), {"-I", PROXGEN_RUNTIME_DIR, (s / "main.cpp").string()});
  args.insert(args.end(), sources.begin(), sources.end());
  args.insert(args.end(), {"-o", (s / "program").string()});
  ProcessResult r = test::runProgram(compiler(), args);
  ASSERT_EQ(r.code, 0) << r.err.substr(0, 4000);
  r = test::runProgram((s / "program").string(), {});
  EXPECT_EQ(r.code, 0) << "a solver returned NaN at the zero state";
}

}  // namespace
}  // namespace proxgen
