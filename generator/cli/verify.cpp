// proxgen verify (placeholder until implemented; exits 2).
#include <cstdio>
#include <cstdlib>

#include "cli/commands.hpp"

namespace proxgen::cli {

void addVerify(CLI::App& app) {
  auto* cmd = app.add_subcommand("verify", "not implemented yet");
  cmd->allow_extras();
  cmd->callback([] {
    std::fprintf(stderr, "proxgen: verify is not implemented yet\n");
    std::exit(2);
  });
}

}  // namespace proxgen::cli
