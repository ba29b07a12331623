// States (q, v, tau) and results as JSON keyed by joint and constraint names
// (README, "States and results (JSON)"), through nlohmann-json.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <random>
#include <string>
#include <vector>

#include "model/model.hpp"

namespace proxgen {

/// Largest state file read (bytes), and most JSON values (numbers, strings,
/// lists and objects) in one: nlohmann-json's DOM takes 16 bytes per value plus
/// ~80 per object member, so 4,194,304 values cost under 0.5 GB beside the
/// text; the largest robot (4101 DoF) needs ~12,300 per state, so a file holds
/// over 300 of its states (docs/guarantees.md).
inline constexpr std::size_t kMaxStateBytes = 64u << 20;
inline constexpr std::size_t kMaxStateValues = 1u << 22;

struct State {
  VecX q, v, tau;
};

/// Reads one state object. Every joint must appear in q and v; a joint missing
/// from tau gets 0. The free-flyer quaternion and a planar joint's (cos, sin)
/// must have a finite, non-zero norm and are normalised. `where` names the file and the element for messages.
State stateFromJson(const Model& model, const nlohmann::json& j, const std::string& where);

/// Reads a file holding one state object or a list of them. `isList` tells which.
/// A state file's JSON, read and parsed with every bound and check loadStates
/// applies (regular file, size, nesting, value count, no repeated key), for
/// readers of states with more keys (eval --compute's qdd and lambda).
nlohmann::json readStateJson(const std::string& path);
std::vector<State> loadStates(const Model& model, const std::string& path, bool* isList = nullptr);

/// A joint-space vector (nv) keyed by joint name: scalars, or 6-vectors for a
/// free flyer, 3-vectors for a planar joint.
nlohmann::json velocityToJson(const Model& model, const VecX& x);
/// A configuration (nq) keyed by joint name.
nlohmann::json configurationToJson(const Model& model, const VecX& q);
/// Stacked constraint rows keyed by constraint name.
nlohmann::json rowsToJson(const System& sys, const VecX& lambda);

/// Reads a joint-space vector keyed by joint name (the inverse of velocityToJson).
VecX velocityFromJson(const Model& model, const nlohmann::json& j, const std::string& where, bool missingIsZero);
VecX configurationFromJson(const Model& model, const nlohmann::json& j, const std::string& where);

/// A random state for tests and `verify`: joints uniform inside their limits
/// (in [-1, 1] rad or m without limits), a uniformly random unit quaternion and
/// base position in [-1, 1]^3, a planar joint's yaw uniform in [-pi, pi] and
/// position in [-1, 1]^2, velocities and torques uniform in [-1, 1].
State randomState(const Model& model, std::mt19937& rng);

}  // namespace proxgen
