// State JSON text -> State against a fixed small model: tests/data/good/arm3.urdf on a
// floating base (so the quaternion path is reached) and on a fixed base. The
// text is parsed the way loadStates does (nlohmann::json::parse); a parse error
// is the expected answer to malformed JSON, any other exception is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "fuzz_common.hpp"
#include "model/state.hpp"
#include "model/urdf.hpp"

namespace {

const proxgen::Model& arm(bool floating) {
  static const proxgen::Model fixed = proxgen::loadUrdf(PROXGEN_FUZZ_DATA_DIR "/good/arm3.urdf", false);
  static const proxgen::Model free = proxgen::loadUrdf(PROXGEN_FUZZ_DATA_DIR "/good/arm3.urdf", true);
  return floating ? free : fixed;
}

// What stateFromJson promises about a state it returns.
void checkState(const proxgen::Model& m, const proxgen::State& s) {
  if (s.q.size() != m.nq || s.v.size() != m.nv || s.tau.size() != m.nv) proxgen::fuzz::broken("state sizes", "");
  if (!s.q.allFinite() || !s.v.allFinite() || !s.tau.allFinite()) proxgen::fuzz::broken("non-finite state", "");
  if (m.floatingBase && std::abs(s.q.segment<4>(3).norm() - 1.0) > 1e-12)
    proxgen::fuzz::broken("quaternion not normalised", "");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(data, data + size);
  } catch (const nlohmann::json::exception&) {
    return 0;  // loadStates turns this into a proxgen::Error naming the file
  }
  const auto items = j.is_array() ? j : nlohmann::json::array({j});
  for (bool floating : {false, true}) {
    for (const auto& item : items) {
      PROXGEN_FUZZ_GUARD(checkState(arm(floating), proxgen::stateFromJson(arm(floating), item, "fuzz.json")));
    }
  }
  return 0;
}
