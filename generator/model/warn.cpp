#include "model/warn.hpp"

#include <cstdio>
#include <mutex>
#include <utility>
#include <vector>

#include "model/error.hpp"

namespace proxgen {
namespace {

std::mutex g_sinkMutex;
WarningSink g_sink;               // empty: held in g_held
std::vector<std::string> g_held;  // for flushWarnings
// As long as the CLI lets an error line be (cli/main.cpp): a path and a reason.
constexpr std::size_t kMaxWarningShown = 1000;

}  // namespace

std::string warn(const std::string& file, const std::string& element, const std::string& what) {
  return warnLine(describe(file, element, what));
}

std::string warnLine(const std::string& line) {
  std::lock_guard<std::mutex> lock(g_sinkMutex);
  if (g_sink) g_sink(line);
  else g_held.push_back(line);
  return line;
}

void flushWarnings() {
  std::lock_guard<std::mutex> lock(g_sinkMutex);
  for (const std::string& line : g_held)
    std::fprintf(stderr, "proxgen: warning: %s\n", oneLine(line, kMaxWarningShown).c_str());
  g_held.clear();
}

WarningSink setWarningSink(WarningSink sink) {
  std::lock_guard<std::mutex> lock(g_sinkMutex);
  return std::exchange(g_sink, std::move(sink));
}

}  // namespace proxgen
