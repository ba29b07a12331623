// Must NOT link: uses operator new / delete. Built only by the `heap_guard_new` test.
// (The pointer escapes into a global: a new/delete pair in one function may be elided.)
volatile int g_count = 8;
int* volatile g_block = nullptr;

int main() {
  g_block = new int[g_count];
  g_block[0] = 1;
  const int rc = g_block[0] - 1;
  delete[] g_block;
  return rc;
}
