// proxgen: constrained-dynamics solver generator. See README.md.
#include <fmt/format.h>

#include <cstdio>

#include "cli/commands.hpp"
#include "model/error.hpp"
#include "model/warn.hpp"

int main(int argc, char** argv) {
  CLI::App app{"proxgen " PROXGEN_VERSION ": generates flat C++ constrained-dynamics solvers for one robot"};
  app.set_version_flag("--version", "proxgen " PROXGEN_VERSION);
  app.require_subcommand(1);
  proxgen::cli::addCheck(app);
  proxgen::cli::addEval(app);
  proxgen::cli::addGenerate(app);
  proxgen::cli::addVerify(app);
  try {
    app.parse(argc, argv);
    proxgen::flushWarnings();  // only once the command succeeded: bad input prints one line
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const proxgen::Error& e) {
    std::fprintf(stderr, "proxgen: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "proxgen: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
