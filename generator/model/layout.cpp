// Layout YAML -> Layout (yaml-cpp). Every value is checked for type, range and
// finiteness, and every error names the file, the line and the element.
#include "model/layout.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <sstream>

#include "model/error.hpp"
#include "model/input.hpp"
#include "model/urdf.hpp"

namespace proxgen {
namespace {

inline constexpr std::size_t kMaxLayoutBytes = 4u << 20;

class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void failAt(const YAML::Node& node, const std::string& element, const std::string& what) const {
    const YAML::Mark m = node.Mark();
    const std::string file = m.is_null() ? path_ : fmt::format("{}:{}", path_, m.line + 1);
    fail(file, element, what);
  }

  // Unknown keys and repeated keys are errors: yaml-cpp keeps both entries of
  // `mu: 1` then `mu: -5` and a lookup finds the first, so the second would be
  // neither used nor checked.
  void onlyKeys(const YAML::Node& map, const std::string& element, std::initializer_list<const char*> keys) const {
    if (!map.IsMap()) failAt(map, element, "expected a mapping");
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) failAt(kv.first, element, "a key must be a plain name");
      const std::string key = kv.first.Scalar();
      if (!seen.insert(key).second)
        failAt(kv.first, element.empty() ? quoted(key) : fmt::format("{}.{}", element, key),
               "the key appears twice in the same mapping");
      bool known = false;
      for (const char* k : keys) known = known || key == k;
      if (!known) {
        std::string list;
        for (const char* k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
        failAt(kv.first, element, fmt::format("unknown key {} (expected one of: {})", quoted(key), list));
      }
    }
  }

  double number(const YAML::Node& n, const std::string& element) const {
    if (!n.IsScalar()) failAt(n, element, "expected a number");
    // Parsed in the classic locale by hand: yaml-cpp's as<double> accepts
    // ".inf"/".nan", which are never valid here.
    std::istringstream in(n.Scalar());
    in.imbue(std::locale::classic());
    double x = 0;
    in >> x;
    if (in.fail() || !(in >> std::ws).eof()) failAt(n, element, fmt::format("{} is not a number", quoted(n.Scalar())));
    if (!std::isfinite(x)) failAt(n, element, fmt::format("{} is not finite", quoted(n.Scalar())));
    if (std::abs(x) > kMaxInputMagnitude)
      failAt(n, element,
             fmt::format("{} is beyond the largest magnitude proxgen accepts ({:g}): the dynamics would overflow",
                         quoted(n.Scalar()), kMaxInputMagnitude));
    return x;
  }

  int integer(const YAML::Node& n, const std::string& element) const {
    const double x = number(n, element);
    if (x != std::floor(x) || std::abs(x) > 2e9) failAt(n, element, fmt::format("{} is not an integer", quoted(n.Scalar())));
    return int(x);
  }

  std::string string(const YAML::Node& n, const std::string& element) const {
    if (!n.IsScalar()) failAt(n, element, "expected a string");
    if (n.Scalar().empty()) failAt(n, element, "is empty");
    std::size_t at = 0;
    if (!isValidUtf8(n.Scalar(), &at))
      failAt(n, element,
             fmt::format("is not valid UTF-8 (byte 0x{:02x} at offset {}); names must be UTF-8 text",
                         static_cast<unsigned char>(n.Scalar()[at]), at));
    return n.Scalar();
  }

  Vec3 vec3(const YAML::Node& n, const std::string& element) const {
    if (!n.IsSequence() || n.size() != 3) failAt(n, element, "expected a list of 3 numbers");
    return {number(n[0], element), number(n[1], element), number(n[2], element)};
  }

  SE3 placement(const YAML::Node& n, const std::string& element) const {
    onlyKeys(n, element, {"xyz", "rpy"});
    SE3 M;
    if (n["xyz"]) M.p = vec3(n["xyz"], element + ".xyz");
    if (n["rpy"]) M.R = snapRotation(rpyToMatrix(vec3(n["rpy"], element + ".rpy")));  // as a URDF origin's
    return M;
  }

  Constraint constraint(const YAML::Node& n, std::size_t index) const {
    const std::string element = fmt::format("constraints[{}]", index);
    onlyKeys(n, element, {"name", "link", "type", "offset", "kp", "kd", "target"});
    for (const char* key : {"name", "link", "type"})
      if (!n[key]) failAt(n, element, fmt::format("missing key '{}'", key));
    Constraint c;
    c.name = string(n["name"], element + ".name");
    const std::string el = fmt::format("{} {}", element, quoted(c.name));
    c.link = string(n["link"], el + ".link");
    if (!n["link"].Mark().is_null()) c.linkLine = n["link"].Mark().line + 1;  // for an unknown link (bindLayout)
    const std::string type = string(n["type"], el + ".type");
    if (type == "6d" || type == "6D") c.type = ConstraintType::Weld6D;
    else if (type == "3d" || type == "3D") c.type = ConstraintType::Point3D;
    else failAt(n["type"], el + ".type", fmt::format("unknown constraint type {} (expected 6d or 3d)", quoted(type)));
    if (n["offset"]) c.offset = placement(n["offset"], el + ".offset");
    if (n["kp"]) c.kp = number(n["kp"], el + ".kp");
    if (n["kd"]) c.kd = number(n["kd"], el + ".kd");
    if (c.kp < 0 || c.kd < 0) failAt(n, el, "Baumgarte gains kp and kd must be >= 0");
    if (n["target"]) {
      c.target = placement(n["target"], el + ".target");
      c.hasTarget = true;
    }
    if (c.kp != 0 && !c.hasTarget) failAt(n, el, "kp is not zero but no target placement is given");
    return c;
  }

  // `functions: [a, b]`: what a generated solver holds (model/functions.hpp);
  // each name is checked at its own line.
  FunctionSet functions(const YAML::Node& list) const {
    if (!list.IsSequence()) failAt(list, "functions", "expected a list of function names (valid: " + functionNameList() + ")");
    if (list.size() == 0) failAt(list, "functions", "is empty (valid: " + functionNameList() + ")");
    FunctionSet set = FunctionSet::none();
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string element = fmt::format("functions[{}]", k);
      const std::string name = string(list[k], element);
      Function f;
      if (!parseFunctionName(name, f))
        failAt(list[k], element, fmt::format("unknown function {} (valid: {})", quoted(name), functionNameList()));
      if (set.has(f)) failAt(list[k], element, fmt::format("function {} is listed twice", quoted(name)));
      set.add(f);
    }
    return set;
  }

  Layout layout(const YAML::Node& root) const {
    Layout L;
    L.sourcePath = path_;
    if (!root.IsMap())
      failAt(root, "", "expected a mapping with keys base, gravity, mu, iterations, functions, constraints");
    onlyKeys(root, "", {"base", "gravity", "mu", "iterations", "functions", "constraints"});
    if (root["base"]) {
      const std::string base = string(root["base"], "base");
      if (base != "floating" && base != "fixed" && base != "planar")
        failAt(root["base"], "base", fmt::format("{} is none of 'fixed', 'floating', 'planar'", quoted(base)));
      L.floatingBase = base == "floating";
      L.planarBase = base == "planar";
    }
    if (root["gravity"]) {
      L.gravity = vec3(root["gravity"], "gravity");
      L.hasGravity = true;
    }
    if (root["mu"]) {
      L.mu = number(root["mu"], "mu");
      if (!(L.mu > 0)) failAt(root["mu"], "mu", "the penalty mu must be > 0");
      // The solvers use 1/mu (proxPV, proxLTL): below 1/kMaxInputMagnitude it
      // would leave the range every other input keeps to.
      if (L.mu < 1.0 / kMaxInputMagnitude)
        failAt(root["mu"], "mu", fmt::format("{:g} is below the smallest penalty proxgen accepts ({:g}): 1/mu would overflow "
                                             "the solvers",
                                             L.mu, 1.0 / kMaxInputMagnitude));
    }
    if (root["iterations"]) {
      L.iterations = integer(root["iterations"], "iterations");
      if (L.iterations < 0 || L.iterations > kMaxIterations)
        failAt(root["iterations"], "iterations", fmt::format("{} is outside [0, {}]", L.iterations, kMaxIterations));
    }
    if (root["functions"]) L.functions = functions(root["functions"]);
    if (root["constraints"]) {
      const YAML::Node list = root["constraints"];
      if (list.IsNull()) return L;
      if (!list.IsSequence()) failAt(list, "constraints", "expected a list");
      std::set<std::string> names;
      int rows = 0;
      for (std::size_t k = 0; k < list.size(); ++k) {
        Constraint c = constraint(list[k], k);
        if (!names.insert(c.name).second)
          failAt(list[k], fmt::format("constraints[{}]", k), fmt::format("duplicate constraint name {}", quoted(c.name)));
        rows += c.rows();
        if (rows > kMaxConstraintRows)
          failAt(list[k], fmt::format("constraints[{}]", k),
                 fmt::format("more than {} constraint rows: proxgen reads layouts of at most {} rows", kMaxConstraintRows,
                             kMaxConstraintRows));
        L.constraints.push_back(std::move(c));
      }
    }
    return L;
  }

 private:
  std::string path_;
};

}  // namespace

Layout parseLayout(const std::string& yaml, const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    fail(e.mark.is_null() ? path : fmt::format("{}:{}", path, e.mark.line + 1), "", fmt::format("malformed YAML: {}", oneLine(e.msg)));
  }
  try {
    return Reader(path).layout(root);
  } catch (const YAML::Exception& e) {
    fail(e.mark.is_null() ? path : fmt::format("{}:{}", path, e.mark.line + 1), "", fmt::format("invalid layout: {}", oneLine(e.msg)));
  }
}

Layout loadLayout(const std::string& path) { return parseLayout(readInputFile(path, kMaxLayoutBytes, "layout"), path); }

System loadSystem(const std::string& urdfPath, const std::string& layoutPath) {
  const Layout layout = loadLayout(layoutPath);
  return bindLayout(loadUrdf(urdfPath, layout.base()), layout);
}

System loadSystemWithoutLayout(const std::string& urdfPath, bool floatingBase) {
  Layout layout;
  layout.floatingBase = floatingBase;
  return bindLayout(loadUrdf(urdfPath, floatingBase), layout);
}

}  // namespace proxgen
