// proxgen eval (placeholder until implemented; exits 2).
#include <cstdio>
#include <cstdlib>

#include "cli/commands.hpp"

namespace proxgen::cli {

void addEval(CLI::App& app) {
  auto* cmd = app.add_subcommand("eval", "not implemented yet");
  cmd->allow_extras();
  cmd->callback([] {
    std::fprintf(stderr, "proxgen: eval is not implemented yet\n");
    std::exit(2);
  });
}

}  // namespace proxgen::cli
