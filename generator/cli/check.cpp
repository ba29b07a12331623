// proxgen check: what proxgen made of a URDF (and a layout). As text, a summary
// for people: bodies in depth-first order, their joints, merged links, DoF,
// constraint rows and the support set. With --json, the vector layout every
// generated solver uses (README.md, "The generated solver"), so a tool can map
// names to slots. Model warnings (mimic joints, ...) go to stderr.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "model/error.hpp"
#include "model/warn.hpp"
#include "model/layout.hpp"
#include "model/urdf.hpp"

namespace proxgen::cli {
namespace {

using ordered_json = nlohmann::ordered_json;

struct CheckOptions {
  std::string urdf, layout, scalar = "double";
  bool floating = false, json = false;
};

// The layout decides the base; --floating is for a URDF checked without one.
System loadForCheck(const CheckOptions& o) {
  if (o.layout.empty()) return loadSystemWithoutLayout(o.urdf, o.floating);
  const Layout layout = loadLayout(o.layout);
  if (o.floating && !layout.floatingBase)
    fail("command line", "--floating",
         fmt::format("conflicts with {} (its base is {})", o.layout, layout.planarBase ? "planar" : "fixed"));
  return bindLayout(loadUrdf(o.urdf, layout.base()), layout);
}

const char* baseName(const Model& m) { return m.floatingBase ? "floating" : m.planarBase ? "planar" : "fixed"; }

const char* constraintTypeName(ConstraintType t) { return t == ConstraintType::Weld6D ? "6d" : "3d"; }

/// URDF links merged into body i by fixed joints (every frame on i but the body's own link).
std::vector<std::string> mergedLinks(const Model& m, int i) {
  std::vector<std::string> out;
  for (const Frame& f : m.frames)
    if (f.body == i && f.name != m.bodies[i].link) out.push_back(f.name);
  return out;
}

ordered_json vec3Json(const Vec3& x) { return ordered_json::array({x[0], x[1], x[2]}); }

ordered_json jointJson(const Model& m, int i) {
  const Body& b = m.bodies[i];
  const Joint& j = b.joint;
  ordered_json out = {{"name", j.name}, {"type", jointTypeName(j.type)}, {"idx_q", j.idx_q}, {"nq", j.nq},
                      {"idx_v", j.idx_v}, {"nv", j.nv}, {"urdf_type", j.urdfType}, {"body", i}, {"link", b.link}};
  if (j.type != JointType::FreeFlyer) out["axis"] = vec3Json(j.axis);
  if (j.hasPositionLimits || j.velocityLimit != 0 || j.effortLimit != 0) {
    ordered_json limits = ordered_json::object();
    if (j.hasPositionLimits) {
      limits["lower"] = j.lower;
      limits["upper"] = j.upper;
    }
    limits["velocity"] = j.velocityLimit;
    limits["effort"] = j.effortLimit;
    out["limits"] = limits;
  }
  if (!j.mimicOf.empty()) out["mimic"] = j.mimicOf;
  return out;
}

ordered_json constraintJson(const System& sys, const Constraint& c) {
  return {{"name", c.name}, {"link", c.link}, {"type", constraintTypeName(c.type)}, {"row", c.row},
          {"rows", c.rows()}, {"body", c.body}, {"body_link", sys.model.bodies[c.body].link}};
}

ordered_json bodyJson(const Model& m, int i) {
  const Body& b = m.bodies[i];
  return {{"index", i}, {"link", b.link}, {"parent", b.parent}, {"joint", b.joint.name},
          {"merged_links", mergedLinks(m, i)}};
}

ordered_json layoutJson(const System& sys) {
  const Model& m = sys.model;
  ordered_json out = {{"nq", m.nq}, {"nv", m.nv}, {"nc", sys.nc}};
  out["joints"] = ordered_json::array();
  for (int i = 1; i < m.numBodies(); ++i) out["joints"].push_back(jointJson(m, i));
  out["constraints"] = ordered_json::array();
  for (const Constraint& c : sys.constraints) out["constraints"].push_back(constraintJson(sys, c));
  out["bodies"] = ordered_json::array();  // body 0, the world, is the parent 0 of the roots
  for (int i = 1; i < m.numBodies(); ++i) out["bodies"].push_back(bodyJson(m, i));
  out["support"] = sys.supportBodies();
  out["robot"] = m.name;
  out["base"] = baseName(m);
  out["gravity"] = vec3Json(m.gravity);
  out["mu"] = sys.mu;
  out["iterations"] = sys.iterations;
  return out;
}

// A name or path in the summary, escaped like every message (control and C1
// characters, bytes that are not UTF-8), uncut: the summary names links,
// joints and files as they are, and a hostile name must not act on the terminal.
std::string shown(const std::string& text) { return oneLine(text, std::string::npos); }

std::string joinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "-" : out;
}

// Left-aligned columns as wide as their widest cell.
std::string table(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], row[c].size());
    }
  std::string out;
  for (const auto& row : rows) {
    std::string line = " ";
    for (std::size_t c = 0; c < row.size(); ++c) line += fmt::format(" {:<{}}", row[c], c + 1 < row.size() ? width[c] : 0);
    out += line + "\n";
  }
  return out;
}

std::string bodiesText(const Model& m) {
  std::vector<std::vector<std::string>> rows = {{"#", "link", "parent", "joint", "type", "idx_q", "idx_v", "axis", "merged links"}};
  for (int i = 1; i < m.numBodies(); ++i) {
    const Body& b = m.bodies[i];
    const Joint& j = b.joint;
    const std::string axis = j.type == JointType::FreeFlyer ? "-" : fmt::format("[{}, {}, {}]", j.axis[0], j.axis[1], j.axis[2]);
    rows.push_back({std::to_string(i), shown(b.link), std::to_string(b.parent), shown(j.name), shown(j.urdfType),
                    std::to_string(j.idx_q), std::to_string(j.idx_v), axis, shown(joinNames(mergedLinks(m, i)))});
  }
  return "bodies (depth-first; parent 0 is the world):\n" + table(rows);
}

std::string constraintsText(const System& sys) {
  if (sys.constraints.empty()) return "constraints: none\n";
  std::string out = "constraints (rows in layout order):\n";
  for (const Constraint& c : sys.constraints)
    out += fmt::format("  {:<24} {} on link {} (body {}, {}), rows {}..{}\n", shown(c.name), constraintTypeName(c.type),
                       shown(c.link), c.body, shown(sys.model.bodies[c.body].link), c.row, c.row + c.rows() - 1);
  return out;
}

std::string supportText(const System& sys) {
  std::vector<std::string> names;
  for (int i : sys.supportBodies()) names.push_back(fmt::format("{} {}", i, shown(sys.model.bodies[i].link)));
  return fmt::format("support (bodies on the paths from constrained bodies to the root): {}\n", joinNames(names));
}

std::string summaryText(const System& sys) {
  const Model& m = sys.model;
  std::string out = fmt::format("robot {} ({}), {} base\n", shown(m.name), shown(m.sourcePath), baseName(m));
  if (!sys.layoutPath.empty())
    out += fmt::format("layout {}: mu {}, iterations {}\n", shown(sys.layoutPath), sys.mu, sys.iterations);
  out += fmt::format("gravity [{}, {}, {}]\n", m.gravity[0], m.gravity[1], m.gravity[2]);
  out += fmt::format("nq {}, nv {} (DoF), nc {}, {} moving bodies, {} links\n\n", m.nq, m.nv, sys.nc,
                     m.numBodies() - 1, m.frames.size());
  out += bodiesText(m) + "\n" + constraintsText(sys) + supportText(sys);
  return out;
}

// Float accuracy of constrainedABA (docs/embedded.md, "Float accuracy"): it adds the penalty
// mu K^T K (mu is a mass, kg) to the inertia of every body on the constraint support, so in
// float (unit roundoff u = 2^-24) the lightest one keeps its own inertia only to u mu / m.
// Measured under qemu on a Cortex-M4F at mu = 1e4, the float constrainedABA's relative error
// was 0.05 to 12 times this estimate on the twelve project cases (the ratio moves with the
// order of operations); proxPV does not fold mu into inertias and stayed within 6.1e-4.
// Above 1e-3 (0.1 %) we warn. Massless bodies carry no inertia of their own to lose and are
// skipped.
constexpr double kFloatUnitRoundoff = 0x1p-24;
constexpr double kFloatWarnAbove = 1e-3;

}  // namespace

std::string floatAccuracyWarning(const System& sys) {
  int light = -1;
  for (int b : sys.supportBodies()) {
    const double m = sys.model.bodies[b].inertia.mass;
    if (b > 0 && m > 0 && (light < 0 || m < sys.model.bodies[light].inertia.mass)) light = b;
  }
  if (light < 0) return "";
  const double m = sys.model.bodies[light].inertia.mass;
  const double estimate = kFloatUnitRoundoff * sys.mu / m;
  if (!(estimate > kFloatWarnAbove)) return "";
  return fmt::format(
      "{}: mu = {} and the lightest body on the constraint support is {} ({:.3g} kg): a float solver's "
      "constrained_aba (--scalar float) is expected to lose about 2^-24 * mu / m = {:.1e} relative accuracy "
      "(measured 0.05 to 12 times that); in float use prox_pv, or mu <= {:.2g} with more iterations, or "
      "double (docs/embedded.md, \"Float accuracy\")",
      sys.layoutPath, sys.mu, quoted(sys.model.bodies[light].link), m, estimate, kFloatWarnAbove * m / kFloatUnitRoundoff);
}

void printWarning(const std::string& text) {
  // Held with the loaders' warnings until the command succeeded (model/warn.hpp).
  if (!text.empty()) warnLine(text);
}

namespace {

void runCheck(const CheckOptions& o) {
  const System sys = loadForCheck(o);
  // Built in full before anything is printed: an error leaves stdout empty.
  const std::string out = o.json ? layoutJson(sys).dump(2) + "\n" : summaryText(sys);
  // Only when float is asked for: a double user has nothing to act on.
  if (o.scalar == "float") printWarning(floatAccuracyWarning(sys));
  std::fputs(out.c_str(), stdout);
}

}  // namespace

void addCheck(CLI::App& app) {
  auto opts = std::make_shared<CheckOptions>();
  auto* cmd = app.add_subcommand("check", "model summary: bodies, joints in order, DoF, constraint rows, support");
  cmd->add_option("urdf", opts->urdf, "robot URDF")->required();
  cmd->add_option("--layout", opts->layout, "constraint layout (YAML)");
  cmd->add_flag("--floating", opts->floating, "free-flyer root (without --layout; a layout says `base:`)");
  cmd->add_flag("--json", opts->json, "print the vector layout as JSON (the generated solvers' slots)");
  cmd->add_option("--scalar", opts->scalar, "double (default) or float: with float, warn if the layout costs a float "
                                            "solver accuracy")
      ->check(CLI::IsMember({"double", "float"}));
  cmd->callback([opts] { runCheck(*opts); });
}

}  // namespace proxgen::cli
