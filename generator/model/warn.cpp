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

}  // namespace

std::string warn(const std::string& file, const std::string& element, const std::string& what) {
  const std::string line = describe(file, element, what);
  std::lock_guard<std::mutex> lock(g_sinkMutex);
  if (g_sink) g_sink(line);
  else g_held.push_back(line);
  return line;
}

void flushWarnings() {
  std::lock_guard<std::mutex> lock(g_sinkMutex);
  for (const std::string& line : g_held) std::fprintf(stderr, "proxgen: warning: %s\n", line.c_str());
  g_held.clear();
}

WarningSink setWarningSink(WarningSink sink) {
  std::lock_guard<std::mutex> lock(g_sinkMutex);
  return std::exchange(g_sink, std::move(sink));
}

}  // namespace proxgen
