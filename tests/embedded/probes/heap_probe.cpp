// Must NOT link: references malloc/free. Built only by the `heap_guard` test, which expects the
// linker to reject it with "heap use is forbidden".
#include <cstdlib>

volatile std::size_t g_size = 64;

int main() {
  void* p = std::malloc(g_size);
  const int rc = p != nullptr ? 0 : 1;
  std::free(p);
  return rc;
}
