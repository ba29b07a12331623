#include "model/state.hpp"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "model/error.hpp"
#include "model/input.hpp"

namespace proxgen {
namespace {

using nlohmann::json;

// A state is at most 4 deep: a list of states, a state, q, a free flyer's (or planar joint's) list.
inline constexpr int kMaxStateDepth = 4;
// An object of a state is keyed by joint names (at most 4096 joints, 4101 with
// a free flyer); bounding it also bounds the keys kept to find repeated ones.
inline constexpr std::size_t kMaxObjectKeys = 8192;

double finiteNumber(const json& x, const std::string& where, const std::string& element) {
  if (!x.is_number()) fail(where, element, fmt::format("expected a number, got {}", x.type_name()));
  return requireMagnitude(where, element, x.get<double>());
}

// Fills `n` slots of out starting at `at` from a number (n == 1) or a list of n numbers.
void readSlots(const json& x, int n, VecX& out, int at, const std::string& where, const std::string& element) {
  if (n == 1 && !x.is_array()) {
    out[at] = finiteNumber(x, where, element);
    return;
  }
  if (!x.is_array() || int(x.size()) != n) fail(where, element, fmt::format("expected a list of {} numbers", n));
  for (int k = 0; k < n; ++k) out[at + k] = finiteNumber(x[k], where, fmt::format("{}[{}]", element, k));
}

void checkKeys(const Model& model, const json& j, const std::string& where, const std::string& field) {
  for (const auto& item : j.items())
    if (model.findJointBody(item.key()) < 0)
      fail(where, fmt::format("{}.{}", field, quoted(item.key())), "is not a joint of the model");
}

json slotsToJson(const VecX& x, int at, int n) {
  if (n == 1) return x[at];
  json a = json::array();
  for (int k = 0; k < n; ++k) a.push_back(x[at + k]);
  return a;
}

}  // namespace

VecX configurationFromJson(const Model& model, const json& j, const std::string& where) {
  if (!j.is_object()) fail(where, "q", "expected an object keyed by joint name");
  checkKeys(model, j, where, "q");
  VecX q(model.nq);
  for (int i = 1; i < model.numBodies(); ++i) {
    const Joint& jt = model.bodies[i].joint;
    const std::string element = fmt::format("q.{}", quoted(jt.name));
    if (!j.contains(jt.name)) fail(where, element, "missing");
    if (jt.type != JointType::FreeFlyer && jt.type != JointType::Planar) {
      readSlots(j.at(jt.name), jt.nq, q, jt.idx_q, where, element);
      continue;
    }
    // A free flyer [x y z qx qy qz qw] or a planar joint [x y cos(yaw) sin(yaw)]:
    // positions, then a direction (the quaternion, or (cos, sin)).
    const bool ff = jt.type == JointType::FreeFlyer;
    const int positions = ff ? 3 : 2, n = jt.nq;
    const json& x = j.at(jt.name);
    // The count given and the order expected: a pose with roll-pitch-yaw (6
    // numbers) or a bare quaternion (4) is the usual mistake.
    if (!x.is_array() || int(x.size()) != n)
      fail(where, element,
           fmt::format("expected a list of {} numbers {} for {} joint {} ({}), got {}", n,
                       ff ? "[x y z qx qy qz qw]" : "[x y cos(yaw) sin(yaw)]", ff ? "free-flyer" : "planar",
                       quoted(jt.name),
                       ff ? "position, then the quaternion with w last" : "position, then the direction of yaw",
                       x.is_array() ? fmt::format("a list of {}", x.size()) : std::string(x.type_name())));
    for (int k = 0; k < positions; ++k) q[jt.idx_q + k] = finiteNumber(x[k], where, fmt::format("{}[{}]", element, k));
    // The direction's components only give a direction: any finite size is
    // accepted, and it is normalised by its largest component first, so that
    // [1e200, 1e200, 1e200, 1e200] is [0.5, 0.5, 0.5, 0.5] (its squared norm
    // would overflow) and a tiny one does not underflow to zero.
    VecX dir(n - positions);
    for (int k = 0; k < n - positions; ++k) {
      const std::string el = fmt::format("{}[{}]", element, k + positions);
      if (!x[k + positions].is_number())
        fail(where, el, fmt::format("expected a number, got {}", x[k + positions].type_name()));
      dir[k] = x[k + positions].get<double>();
      if (!std::isfinite(dir[k])) fail(where, el, "is not finite");
    }
    const double largest = dir.cwiseAbs().maxCoeff();
    if (!(largest > 0))
      fail(where, element, ff ? "the quaternion [qx qy qz qw] has zero norm" : "the yaw direction [cos sin] is [0, 0]");
    dir /= largest;  // now the largest component is +-1: no overflow, no underflow below
    // Documented: normalised. In fixed sizes, so the quaternion's rounding is the
    // one it always had (a dynamic-size norm may sum in another order).
    if (ff) {
      const Eigen::Vector4d quat = dir;
      q.segment<4>(jt.idx_q + 3) = quat / quat.norm();
    } else {
      const Eigen::Vector2d cs = dir;
      q.segment<2>(jt.idx_q + 2) = cs / cs.norm();
    }
  }
  return q;
}

VecX velocityFromJson(const Model& model, const json& j, const std::string& where, bool missingIsZero) {
  VecX x = VecX::Zero(model.nv);
  const std::string field = missingIsZero ? "tau" : "v";
  if (!j.is_object()) fail(where, field, "expected an object keyed by joint name");
  checkKeys(model, j, where, field);
  for (int i = 1; i < model.numBodies(); ++i) {
    const Joint& jt = model.bodies[i].joint;
    const std::string element = fmt::format("{}.{}", field, quoted(jt.name));
    if (!j.contains(jt.name)) {
      if (missingIsZero) continue;
      fail(where, element, "missing");
    }
    readSlots(j.at(jt.name), jt.nv, x, jt.idx_v, where, element);
  }
  return x;
}

State stateFromJson(const Model& model, const json& j, const std::string& where) {
  if (!j.is_object()) fail(where, "", "a state must be an object with keys q, v and optionally tau");
  for (const auto& item : j.items())
    if (item.key() != "q" && item.key() != "v" && item.key() != "tau")
      fail(where, quoted(item.key()), "unknown key (expected q, v, tau)");
  if (!j.contains("q")) fail(where, "q", "missing");
  if (!j.contains("v")) fail(where, "v", "missing");
  State s;
  s.q = configurationFromJson(model, j.at("q"), where);
  s.v = velocityFromJson(model, j.at("v"), where, false);
  s.tau = j.contains("tau") ? velocityFromJson(model, j.at("tau"), where, true) : VecX::Zero(model.nv);
  return s;
}

json readStateJson(const std::string& path) {
  const std::string text = readInputFile(path, kMaxStateBytes, "state");
  json j;
  // The last key read tells the user where a bad token (e.g. an overflowing
  // 1e999, which nlohmann reports as out_of_range, not parse_error) was. The
  // same callback refuses, while parsing, what the DOM would otherwise hold:
  // nesting deeper than a state has (64 MiB of `[[[[...` took 2.4 GB as a
  // DOM), more than kMaxStateValues values, and a key repeated in one object
  // (nlohmann keeps the last one silently).
  std::string lastKey;
  std::vector<std::set<std::string>> openObjects;
  std::size_t values = 0;
  const json::parser_callback_t track = [&](int depth, json::parse_event_t event, json& parsed) {
    using E = json::parse_event_t;
    if ((event == E::object_start || event == E::array_start) && depth >= kMaxStateDepth)
      fail(path, lastKey.empty() ? "" : fmt::format("after key {}", proxgen::quoted(lastKey)),
           fmt::format("nested more than {} levels deep: a state file is a list of states of q, v, tau "
                       "(proxgen reads at most {} levels)",
                       kMaxStateDepth, kMaxStateDepth));
    if (event == E::object_start) openObjects.emplace_back();
    if (event == E::object_end && !openObjects.empty()) openObjects.pop_back();
    if (event == E::key) {
      lastKey = parsed.get<std::string>();
      if (!openObjects.empty() && !openObjects.back().insert(lastKey).second)
        fail(path, fmt::format("key {}", proxgen::quoted(lastKey)), "appears twice in the same object");
      if (!openObjects.empty() && openObjects.back().size() > kMaxObjectKeys)
        fail(path, fmt::format("key {}", proxgen::quoted(lastKey)),
             fmt::format("is one key too many: an object of a state has one key per joint, at most {}", kMaxObjectKeys));
    }
    if ((event == E::value || event == E::object_start || event == E::array_start) && ++values > kMaxStateValues)
      fail(path, "", fmt::format("holds more than {} values: proxgen reads state files of at most {} numbers, lists and "
                                 "objects",
                                 kMaxStateValues, kMaxStateValues));
    return true;
  };
  try {
    j = json::parse(text, track);
  } catch (const json::exception& e) {
    fail(path, lastKey.empty() ? "" : fmt::format("after key {}", proxgen::quoted(lastKey)), fmt::format("invalid JSON: {}", oneLine(e.what())));
  }
  return j;
}

std::vector<State> loadStates(const Model& model, const std::string& path, bool* isList) {
  const json j = readStateJson(path);
  std::vector<State> states;
  if (isList) *isList = j.is_array();
  if (j.is_array()) {
    for (std::size_t k = 0; k < j.size(); ++k) states.push_back(stateFromJson(model, j[k], fmt::format("{}: [{}]", path, k)));
  } else {
    states.push_back(stateFromJson(model, j, path));
  }
  return states;
}

json velocityToJson(const Model& model, const VecX& x) {
  json out = json::object();
  for (int i = 1; i < model.numBodies(); ++i) {
    const Joint& jt = model.bodies[i].joint;
    out[jt.name] = slotsToJson(x, jt.idx_v, jt.nv);
  }
  return out;
}

json configurationToJson(const Model& model, const VecX& q) {
  json out = json::object();
  for (int i = 1; i < model.numBodies(); ++i) {
    const Joint& jt = model.bodies[i].joint;
    out[jt.name] = slotsToJson(q, jt.idx_q, jt.nq);
  }
  return out;
}

json rowsToJson(const System& sys, const VecX& lambda) {
  json out = json::object();
  for (const Constraint& c : sys.constraints) out[c.name] = slotsToJson(lambda, c.row, c.rows());
  return out;
}

State randomState(const Model& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  State s{VecX::Zero(m.nq), VecX::Zero(m.nv), VecX::Zero(m.nv)};
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    if (j.type == JointType::FreeFlyer) {
      for (int k = 0; k < 3; ++k) s.q[j.idx_q + k] = U(rng);
      const Eigen::Vector4d quat(N(rng), N(rng), N(rng), N(rng));  // normal -> uniform on the sphere
      s.q.segment<4>(j.idx_q + 3) = quat.normalized();
    } else if (j.type == JointType::Planar) {
      // Position in [-1, 1]^2, yaw uniform in [-pi, pi]: (cos, sin) exactly unit to rounding.
      for (int k = 0; k < 2; ++k) s.q[j.idx_q + k] = U(rng);
      const double yaw = 3.141592653589793 * U(rng);
      s.q[j.idx_q + 2] = std::cos(yaw);
      s.q[j.idx_q + 3] = std::sin(yaw);
    } else if (j.hasPositionLimits && j.upper > j.lower && std::isfinite(j.upper - j.lower)) {
      s.q[j.idx_q] = std::uniform_real_distribution<double>(j.lower, j.upper)(rng);
    } else {
      s.q[j.idx_q] = U(rng);
    }
  }
  for (int k = 0; k < m.nv; ++k) s.v[k] = U(rng);
  for (int k = 0; k < m.nv; ++k) s.tau[k] = U(rng);
  return s;
}

}  // namespace proxgen
