// Must NOT link: uses operator new / delete. Built only by the `new_guard` test.
volatile int g_count = 8;

int main() {
  int* p = new int[g_count];
  p[0] = 1;
  const int rc = p[0] - 1;
  delete[] p;
  return rc;
}
