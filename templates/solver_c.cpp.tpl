R"proxgen({banner}
// The C interface of {name}.hpp, declared in {name}_c.h: each function
// copies its scalar arguments into a Settings, makes the caller's buffer the
// Workspace and calls the C++ function. The Workspace is a trivial type: the
// placement new runs no code and writes nothing (it begins the object's
// lifetime in the caller's storage), and no heap is touched.
#include "{name}_c.h"

#include <new>
#include <type_traits>

#include "{name}.hpp"

static_assert(std::is_same_v<{name}::Scalar, {scalar}>, "{name}_c.h is for another scalar");
static_assert(std::is_trivially_default_constructible_v<{name}::Workspace> &&
                  std::is_trivially_destructible_v<{name}::Workspace>,
              "the work buffer needs a trivial Workspace");
static_assert(sizeof({name}::Workspace) == {prefix}_WORK_SIZE, "{name}_c.h's work size is not the Workspace's");
static_assert({prefix}_WORK_ALIGN % alignof({name}::Workspace) == 0, "{name}_c.h's alignment does not suffice");
static_assert({prefix}_NQ == {name}::nq && {prefix}_NV == {name}::nv && {prefix}_NC == {name}::nc &&
                  {prefix}_NCONS == {name}::ncons,
              "{name}_c.h's sizes are not {name}.hpp's");

namespace {{

{name}::Workspace& workspaceIn(void* work) noexcept {{ return *::new (work) {name}::Workspace; }}
{helpers}}}  // namespace

extern "C" {{

size_t {prefix}_work_size(void) noexcept {{ return sizeof({name}::Workspace); }}
size_t {prefix}_work_align(void) noexcept {{ return {prefix}_WORK_ALIGN; }}
{definitions}}}  // extern "C"
)proxgen"
