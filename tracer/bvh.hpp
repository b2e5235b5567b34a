// Bounding volume hierarchy built with the binned surface area heuristic.
// The builder sees only primitive boxes, so the tree (and with it the order
// in which a ray meets primitives) does not depend on how it is later packed.
// Output invariants: nodes[0] is the root; each node's two children are either
// nodes (count == 0, child = node index > parent's index) or leaves of
// 1..max_leaf primitives, which are consecutive in `order` (order[k] is the
// original index of the k-th primitive). With no primitives, nodes[0] is
// all empty and must not be traversed.
#pragma once

#include <cstdint>
#include <vector>

#include "tracer/database.hpp"
#include "tracer/geometry.hpp"

namespace tracer {

struct BvhBuild {
  std::vector<BvhNode> nodes;
  std::vector<std::uint32_t> order;
  std::uint32_t depth = 1;  // nodes on the longest root-to-leaf path
};

BvhBuild build_bvh(const std::vector<Box3f>& prim_bounds, int max_leaf);

}  // namespace tracer
