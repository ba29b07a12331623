// Where the passes' statements go: a host function (kinematics,
// constrained_aba, ...) whose body is a list of calls to part functions, each
// holding a few bodies' blocks of one pass; small functions keep the
// compiler's time linear in the robot's size. The entry point calls
// beginPass() before each pass (a one-line banner at the call site), a pass
// calls boundary() before each block; the writer closes the current part when
// it is full or the pass ends, names it after its host, its pass and the
// bodies it holds (caba_backward_LF_foot_to_LF_hip), decides its parameters
// from what its printed statements read and write (the expression graph, not
// the text), and moves the live pass outputs (body_state.hpp's Live) into the
// next function.
#pragma once

#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "emit/body_state.hpp"
#include "emit/expr.hpp"

namespace proxgen::emit {

class FunctionWriter {
 public:
  /// `bodyName(i)`: how part names spell body i (the plan's identifier);
  /// `bodyShapes(i)`: its subtree's shape (BodyPlan::shape).
  FunctionWriter(ScalarType scalar, std::vector<std::string> bodyNames, std::vector<std::string> bodyShapes)
      : scalar_(scalar), bodyNames_(std::move(bodyNames)), bodyShapes_(std::move(bodyShapes)) {}

  /// The builder statements go to now (a part, or the host between parts).
  CodeBuilder& cb() { return *cb_; }
  const CodeBuilder* current() const { return cb_; }
  /// The pass outputs in scope: set by the caller, moved at every boundary.
  Live& live() { return live_; }

  /// Opens a host function; the live outputs move in from `from` (null: none yet).
  /// Hosts nest (a host opened inside another is closed before it continues).
  void beginHost(const std::string& name, const CodeBuilder* from);
  /// Starts a pass in the current host: closes the open part; the next parts
  /// are named <host>_<name>_<range> (<host>_<range> for an empty name), and
  /// `banner` is printed as "// ---- banner" above the first of their calls.
  void beginPass(const std::string& name, const std::string& banner);
  /// Before a block of body `body`: opens a part function, or a new one when
  /// this one is full; not when the block before was its twin's (the same
  /// shape), so that the two can run as a pair (docs/emitter.md, "Blocks in pairs").
  void boundary(int body);
  /// Before a block that is not a body's: `label` names it ("column_3").
  void boundary(const std::string& label);
  /// Closes the current part (if any): prints it and its call in the host.
  void endPart();
  /// Closes the host: its body text; its builder stays alive (hostBuilder()) for
  /// later imports of its outputs.
  std::string endHost(const std::vector<std::string>& params);
  const CodeBuilder* lastHost() const { return lastHost_; }

  /// The host's mu and 1/mu (defined in the host, passed to parts). Their
  /// definitions are raw texts, `s.mu * Scalar(s.iterations > 0)` and
  /// `1 / s.mu`: one multiplication and one division, counted here.
  void setHostMu(const Expr& mu);
  void setHostInvMu(const Expr& inv);
  /// The operations of a closed host, its part functions included (not the
  /// hosts it calls by a raw line: kinematics(...), ...); zero if none closed.
  OpCount hostOps(const std::string& name) const;

  /// A name a part function may not take (a function of the file besides the
  /// parts): a part that would is suffixed _2, as when two parts collide.
  void reserveName(const std::string& name) { partNames_.insert(name); }
  /// Every part function printed so far.
  const std::string& parts() const { return partsText_; }
  /// The host a part function was printed for ("" if none of that name).
  std::string hostOf(const std::string& part) const {
    const auto it = partHost_.find(part);
    return it == partHost_.end() ? std::string() : it->second;
  }
  const CodeBuilder::Stats& stats() const { return stats_; }
  const std::shared_ptr<NameTable>& names() const { return names_; }

  /// Statements per part (before dead-code removal): measured best.
  static constexpr int kPartBudget = 40;

 private:
  struct Host {
    std::string name;
    std::unique_ptr<CodeBuilder> cb;
    Expr mu, invMu;
    std::string pass, banner;  // the current pass; its banner until its first call is printed
  };
  void open(const std::string& label);
  std::string partName(const Host& host);
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
  std::vector<std::string> bodyNames_;
  std::string firstLabel_, lastLabel_;  // the open part's first and last block
  std::vector<std::string> bodyShapes_;
  int lastBody_ = -1;    // the block before, when it was a body's in this pass
  bool joined_ = false;  // it was joined to its twin before it
  std::set<std::string> partNames_;
  std::map<std::string, OpCount> hostOps_;
  std::string partsText_;
  std::map<std::string, std::string> partHost_;
  CodeBuilder::Stats stats_;
};

}  // namespace proxgen::emit
