// Layout YAML text -> Layout, then bound to a small fixed model (tests/data/good/arm3.urdf)
// so that link resolution and row assignment see the fuzzed constraints too.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_common.hpp"
#include "model/layout.hpp"
#include "model/urdf.hpp"

namespace {

const proxgen::Model& arm() {
  static const proxgen::Model m = proxgen::loadUrdf(PROXGEN_FUZZ_DATA_DIR "/good/arm3.urdf", false);
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string yaml(reinterpret_cast<const char*>(data), size);
  PROXGEN_FUZZ_GUARD({
    const proxgen::Layout layout = proxgen::parseLayout(yaml, "fuzz.yaml");
    if (!layout.floatingBase) proxgen::bindLayout(arm(), layout);
  });
  return 0;
}
