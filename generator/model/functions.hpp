// Which functions a generated solver holds (issue: the robot-specific dynamics
// library). The layout's `functions: [...]`, `--functions a,b|all` on
// `generate`/`verify` and `FUNCTIONS` in proxgen_add_solver all name them with
// these spellings; the set is exactly what is emitted. The default is the two
// solvers, so a solver generated without a list is what it always was.
#pragma once

#include <string>
#include <vector>

namespace proxgen {

enum class Function {
  ConstrainedAba,
  ProxPv,
  InverseDynamics,
  NonlinearEffects,
  MassMatrix,
  MassMatrixInverse,
  ConstraintPlacements,
  ConstraintJacobian,
  ConstraintDrift,
  Delassus,
  DelassusInverse,
  ConstraintWrenches,
  InverseDynamicsDerivatives,
  ForwardDynamicsDerivatives,
  ConstrainedDynamicsDerivatives,
};

/// Every function, in the order the header declares them.
const std::vector<Function>& allFunctions();
/// The generated function's name ("constrained_aba", "mass_matrix", ...).
const char* functionName(Function f);
/// "a, b, c": every valid name, for error messages.
std::string functionNameList();

class FunctionSet {
 public:
  /// The default: constrained_aba and prox_pv.
  FunctionSet();
  static FunctionSet none();
  static FunctionSet all();

  bool has(Function f) const { return (bits_ >> int(f)) & 1u; }
  void add(Function f) { bits_ |= 1u << int(f); }
  bool empty() const { return bits_ == 0; }
  bool operator==(const FunctionSet& o) const { return bits_ == o.bits_; }
  bool operator!=(const FunctionSet& o) const { return bits_ != o.bits_; }
  /// The names, in allFunctions() order.
  std::vector<std::string> names() const;

 private:
  unsigned bits_ = 0;
};

/// `name` -> Function; false if it is none of them.
bool parseFunctionName(const std::string& name, Function& out);

/// "a,b,c" or "all" (the command line's form) -> the set. An unknown or
/// repeated name, or an empty list, throws proxgen::Error naming `file` and
/// `element` and listing the valid names.
FunctionSet parseFunctionList(const std::string& list, const std::string& file, const std::string& element);

}  // namespace proxgen
