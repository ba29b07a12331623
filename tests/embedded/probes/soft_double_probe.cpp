// Uses double arithmetic on a single-precision FPU. Built with NO_SOFT_DOUBLE only by the
// `soft_double_guard` test, which expects the build to fail.
volatile double g_a = 1.5, g_b = 2.25;

int main() { return g_a * g_b > 3.0 ? 0 : 1; }
