// proxgen: constrained-dynamics solver generator. See README.md.
#include <fmt/format.h>

#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "emit/output.hpp"
#include "model/error.hpp"
#include "model/warn.hpp"

namespace {

// Every message leaves through here: one line, control characters, C1 controls
// and bytes that are not UTF-8 escaped (model/error.hpp oneLine), whoever wrote
// it (our errors, CLI11's, a library's). Long enough for a path and a reason.
constexpr std::size_t kMaxMessage = 1000;

void printError(const char* kind, const std::string& what) {
  std::fprintf(stderr, "proxgen: %s: %s\n", kind, proxgen::oneLine(what, kMaxMessage).c_str());
}

// CLI11 reads an unknown first word (`proxgen chek`) as a stray argument and
// reports "A subcommand is required". The first word that is not an option is
// the command (proxgen itself takes no option with a value): an unknown one is
// named, with the valid ones and, when one is a typo away (two edits, or the
// word begins it), a suggestion. "" when the command is known or absent.
std::string unknownCommand(int argc, char** argv, const std::vector<std::string>& commands) {
  for (int k = 1; k < argc; ++k) {
    const std::string word = argv[k];
    if (!word.empty() && word[0] == '-') continue;
    for (const std::string& c : commands)
      if (word == c) return "";
    std::string valid;
    for (const std::string& c : commands) valid += (valid.empty() ? "" : ", ") + c;
    std::vector<std::string> near;
    for (const std::string& c : commands)
      if (proxgen::editDistance(word, c) <= 2 || (word.size() >= 2 && c.compare(0, word.size(), word) == 0))
        near.push_back(c);
    near = proxgen::closestNames(word, near, 3);
    return proxgen::describe("command line", "", fmt::format("unknown command {} (valid: {}){}", proxgen::quoted(word), valid,
                                                             near.empty() ? "" : "; did you mean " + proxgen::quotedList(near) + "?"));
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"proxgen " PROXGEN_VERSION ": generates flat C++ constrained-dynamics solvers for one robot"};
  app.set_version_flag("--version", "proxgen " PROXGEN_VERSION);
  app.require_subcommand(1);
  proxgen::cli::addCheck(app);
  proxgen::cli::addEval(app);
  proxgen::cli::addGenerate(app);
  proxgen::cli::addVerify(app);
  // An interrupted generate or verify removes its temporaries (emit/output.hpp).
  proxgen::emit::installInterruptCleanup();
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands({})) commands.push_back(sub->get_name());
  if (const std::string unknown = unknownCommand(argc, argv, commands); !unknown.empty()) {
    printError("error", unknown);  // bad input like a bad file: exit 1 (docs/cli.md "Errors")
    return 1;
  }
  try {
    app.parse(argc, argv);
    proxgen::flushWarnings();  // only once the command succeeded: bad input prints one line
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);  // --help, --version: CLI11 prints them, exit 0
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // CLI11's message may quote an argument verbatim (a path after `--` with a
    // newline in it): escaped like ours, on one line. The exit code stays
    // CLI11's (100 and above: command-line syntax, docs/cli.md "Errors").
    printError("error", std::string(e.what()) + " (proxgen --help for usage)");
    return e.get_exit_code();
  } catch (const proxgen::Error& e) {
    printError("error", e.what());
    return 1;
  } catch (const std::exception& e) {
    printError("internal error", e.what());
    return 3;
  }
  return 0;
}
