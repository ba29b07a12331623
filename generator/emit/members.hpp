// The workspace-member registry of one generated solver: every member a pass
// writes is declared here on first use (name, size, comment), in the order the
// code first writes them, which is the order of the Workspace struct.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace proxgen::emit {

/// A per-body quantity: workspace member <prefix>_<ident>.
struct Quantity {
  const char* prefix;
  const char* what;
};
inline constexpr Quantity kQ{"q", "joint offset q"},
    kRJ{"RJ", "joint rotation"}, kV{"v", "velocity"}, kC{"c", "velocity-product acceleration"},
    kPA{"pA", "bias force"}, kIA{"IA", "articulated inertia (upper triangle)"}, kG{"g", "gravity in body coordinates"},
    kOR{"oR", "world rotation"}, kOP{"op", "world position"}, kU{"U", "IA S"}, kDinv{"Dinv", "1 / (S^T IA S)"},
    kL{"L", "Cholesky factor of IA (lower, packed by rows of the upper)"}, kLinv{"Linv", "1 / diag(L)"},
    kUu{"u", "tau - S^T pA"}, kA{"a", "acceleration (gravity-shifted)"}, kDP{"dp", "reduced-sweep force"},
    kKA{"KA", "constraint force directions of the subtree rows (6 x m, one unused column)"},
    kKS{"KS", "S^T KA"}, kKSD{"KSD", "D^-1 S^T KA"}, kZ{"Z", "L^-1 KA (6 x m, one unused column)"},
    kK{"k", "constraint right-hand side"}, kF{"f", "spatial force (inverse dynamics)"},
    kIc{"Ic", "composite inertia: h = m c, then I about the origin (upper triangle)"},
    kFA{"FA", "unit-torque forces, then accelerations, one column per dof (M^-1)"};

class Members {
 public:
  struct Member {
    std::string name;
    int size = 0;  // 0: a scalar
    std::string comment;
    int columns = 0;  // > 0: a matrix of size / columns rows
  };
  /// "w.base" (size 0) or "w.base[idx]"; declares the member on first use.
  std::string member(const std::string& base, int size, int idx, const std::string& comment);
  /// Entry (r, c) of a rows x cols matrix member: "w.base[r][c]".
  std::string member(const std::string& base, int rows, int cols, int r, int c, const std::string& comment);
  /// Entry (r, c + j) of a matrix member (j: a loop variable), "w.base[r][c + j]".
  std::string loopSlot(const std::string& base, int rows, int cols, int r, int c, const std::string& comment);
  /// Slot idx + j of an array member (j: a loop variable), "w.base[idx + j]".
  std::string loopSlot(const std::string& base, int size, int idx, const std::string& comment);
  const std::vector<Member>& all() const { return members_; }
  int scalars() const;
  /// The Workspace struct's member lines.
  std::string declarations() const;

 private:
  std::vector<Member> members_;
  std::map<std::string, int> index_;
};

}  // namespace proxgen::emit
