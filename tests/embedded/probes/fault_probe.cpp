// Executes an undefined instruction: the HardFault handler must report it and exit with
// fw::exit_fault (101) instead of hanging. Run by the `fault_handler` test.
#include "fw/io.hpp"

int main() {
  fw::print("fault_probe: executing udf\n");
  __builtin_trap();
}
