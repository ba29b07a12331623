// The constraint tree of a System (model.hpp, ConstraintTree): computed once
// here, read by the generic solvers (algorithms/data.cpp) and the plan of the
// generated ones (emit/plan.cpp), so both number the rows the same way.
#include "model/model.hpp"

namespace proxgen {

ConstraintTree constraintTree(const System& sys) {
  const Model& m = sys.model;
  const int N = m.numBodies();
  ConstraintTree t;
  t.support = sys.supportBodies();
  t.onSupport.assign(std::size_t(N), 0);
  for (int i : t.support) t.onSupport[std::size_t(i)] = 1;
  // Rows of each subtree: the body's own rows (layout order), then its
  // children's subtrees in child order. Built leaves first (a parent precedes its children).
  t.subtreeRows.assign(std::size_t(N), {});
  for (int i = N - 1; i >= 0; --i) {
    std::vector<int>& rows = t.subtreeRows[std::size_t(i)];
    for (const Constraint& c : sys.constraints)
      if (c.body == i)
        for (int r = 0; r < c.rows(); ++r) rows.push_back(c.row + r);
    for (int ch : m.bodies[std::size_t(i)].children) {
      const std::vector<int>& cr = t.subtreeRows[std::size_t(ch)];
      rows.insert(rows.end(), cr.begin(), cr.end());
    }
  }
  // Where each subtree's rows start in the root's (tree) order: after the
  // parent's start, its own rows and its earlier children's subtrees.
  t.subtreeStart.assign(std::size_t(N), 0);
  t.offsetInParent.assign(std::size_t(N), 0);
  for (int p = 0; p < N; ++p) {
    int offset = int(t.subtreeRows[std::size_t(p)].size());
    for (int ch : m.bodies[std::size_t(p)].children) offset -= int(t.subtreeRows[std::size_t(ch)].size());
    for (int ch : m.bodies[std::size_t(p)].children) {
      t.offsetInParent[std::size_t(ch)] = offset;
      t.subtreeStart[std::size_t(ch)] = t.subtreeStart[std::size_t(p)] + offset;
      offset += int(t.subtreeRows[std::size_t(ch)].size());
    }
  }
  t.treePosition.assign(std::size_t(sys.nc), -1);
  const std::vector<int>& root = t.subtreeRows[0];
  for (std::size_t k = 0; k < root.size(); ++k) t.treePosition[std::size_t(root[k])] = int(k);
  return t;
}

}  // namespace proxgen
