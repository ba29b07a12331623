// Where the passes' statements go: a host function (kinematics,
// constrained_aba, ...) whose body is a list of calls to part functions, each
// holding a few bodies' blocks; small functions keep the compiler's time
// linear in the robot's size. A pass calls boundary() before each block; the
// writer closes the current part when it is full and moves the live pass
// outputs (body_state.hpp's Live) into the next function.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "emit/body_state.hpp"
#include "emit/expr.hpp"

namespace proxgen::emit {

class FunctionWriter {
 public:
  explicit FunctionWriter(ScalarType scalar) : scalar_(scalar) {}

  /// The builder statements go to now (a part, or the host between parts).
  CodeBuilder& cb() { return *cb_; }
  const CodeBuilder* current() const { return cb_; }
  /// The pass outputs in scope: set by the caller, moved at every boundary.
  Live& live() { return live_; }

  /// Opens a host function; the live outputs move in from `from` (null: none yet).
  /// Hosts nest (a host opened inside another is closed before it continues).
  void beginHost(const std::string& name, const CodeBuilder* from);
  /// Before a block: opens a part function, or a new one when this one is full.
  void boundary();
  /// Closes the current part (if any): prints it and its call in the host.
  void endPart();
  /// Closes the host: its body text; its builder stays alive (hostBuilder()) for
  /// later imports of its outputs.
  std::string endHost(const std::vector<std::string>& params);
  const CodeBuilder* lastHost() const { return lastHost_; }

  /// The host's mu and 1/mu (defined in the host, passed to parts).
  void setHostMu(const Expr& mu) { hosts_.back().mu = mu; }
  void setHostInvMu(const Expr& inv) { hosts_.back().invMu = inv; }

  /// Every part function printed so far.
  const std::string& parts() const { return partsText_; }
  const CodeBuilder::Stats& stats() const { return stats_; }
  const std::shared_ptr<NameTable>& names() const { return names_; }

  /// Statements per part (before dead-code removal): measured best.
  static constexpr int kPartBudget = 40;

 private:
  struct Host {
    std::string name;
    std::unique_ptr<CodeBuilder> cb;
    int parts = 0;
    Expr mu, invMu;
  };
  std::string render(CodeBuilder& cb);
  void translate(const CodeBuilder& from, CodeBuilder& to);

  ScalarType scalar_;
  std::shared_ptr<NameTable> names_ = std::make_shared<NameTable>();
  std::vector<Host> hosts_;                           // the open hosts, innermost last
  std::vector<std::unique_ptr<CodeBuilder>> closed_;  // closed hosts: their outputs are imported later
  std::unique_ptr<CodeBuilder> part_;                 // the open part (freed when it closes)
  CodeBuilder* cb_ = nullptr;
  const CodeBuilder* lastHost_ = nullptr;
  Live live_;
  std::string partsText_;
  CodeBuilder::Stats stats_;
};

}  // namespace proxgen::emit
