// Synthetic robots for the scaling study: a serial chain and a complete binary
// tree of n revolute joints on a fixed base, with point contacts (3 rows each)
// spread over the chain or over the tree's leaves. Written as URDF and layout
// text so the study goes through the same loaders as a real robot.
#pragma once

#include <string>

namespace proxgen::bench {

enum class Shape { Chain, Tree };

const char* shapeName(Shape s);

/// URDF of n bodies b1..bn on link `base`. Chain: b_k hangs from b_{k-1}.
/// Tree: b_k hangs from b_{k/2} (heap order), so its depth is about log2(n).
std::string syntheticUrdf(Shape shape, int n);

/// Layout with `contacts` 3D point contacts (m = 3 contacts rows) on distinct
/// bodies: the chain's tip and bodies evenly spaced below it, or leaves of the
/// tree evenly spaced across them. Throws if there are not enough bodies.
std::string syntheticLayout(Shape shape, int n, int contacts);

/// Writes DIR/<shape>_n<n>.urdf and DIR/<shape>_n<n>_c<contacts>.yaml; returns
/// the two paths through urdfPath and layoutPath.
void writeSynthetic(const std::string& dir, Shape shape, int n, int contacts, std::string& urdfPath,
                    std::string& layoutPath);

}  // namespace proxgen::bench
