// proxgen generate (placeholder until implemented; exits 2).
#include <cstdio>
#include <cstdlib>

#include "cli/commands.hpp"

namespace proxgen::cli {

void addGenerate(CLI::App& app) {
  auto* cmd = app.add_subcommand("generate", "not implemented yet");
  cmd->allow_extras();
  cmd->callback([] {
    std::fprintf(stderr, "proxgen: generate is not implemented yet\n");
    std::exit(2);
  });
}

}  // namespace proxgen::cli
