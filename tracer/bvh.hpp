// Bounding volume hierarchy: a binary tree built with the binned surface area
// heuristic, then collapsed to four-wide nodes (each node adopts grandchildren
// of its largest inner children until it has four). The builder sees only
// reference boxes and which references are triangles, so the tree, and with
// it the order in which a ray meets primitives, does not depend on how it is
// later packed into pages, nor on how many threads build it: the nodes and
// `order` are the same bits for every BvhParallelism.
// Output invariants: nodes[0] is the root; an inner lane's node index is
// greater than its parent's, and a node's inner children are consecutive
// (nodes in depth-first order of their sibling groups);
// leaves hold 1..max_leaf references, consecutive in `order` (order[k] is the
// reference index of the k-th leaf entry). With no references, nodes[0] has
// four empty lanes.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "tracer/geometry.hpp"
#include "tracer/huge_pages.hpp"
#include "tracer/records.hpp"

namespace tracer {

struct BvhBuild {
  BigVector<BvhNode> nodes;
  BigVector<std::uint32_t> order;
  std::uint32_t depth = 1;  // nodes on the longest root-to-leaf path
};

// Build references: the boxes the BVH is built over, each naming a primitive.
// A primitive may have several (see split_large_triangles); the BVH copies it
// into every leaf that holds one of its references. triangle[k] says whether
// reference k is a triangle, which a leaf tests four at a time.
struct BuildRefs {
  BigVector<Box3f> bounds;
  BigVector<std::uint32_t> prim;
  std::vector<bool> triangle;
};

// The threads a build may use, and where it starts to use them. Nodes of at
// least `large_node` references are binned and partitioned in chunks of
// `chunk` references shared among threads, and their children at least a
// chunk large may be built on threads of their own. Never more than `threads`
// threads work at once (0 and 1: the caller's only). The defaults suit
// scenes of millions of triangles; tests lower them to reach the parallel
// paths on small scenes. None of it changes the tree.
struct BvhParallelism {
  unsigned threads = 1;
  std::uint32_t large_node = 1u << 16;
  std::uint32_t chunk = 1u << 14;
};

// On an exception in any build thread, waits for all of them to stop, then rethrows it.
BvhBuild build_bvh(const BuildRefs& refs, int max_leaf, const BvhParallelism& parallelism = {});

// Renumbers the nodes so that each page holds a treelet: starting from a
// root, the candidate a ray is most likely to visit next (the largest
// surface area among the children of nodes already placed) joins the page
// until it is full; the candidates left out become roots of later treelets,
// and a treelet that ends before its page does is followed on the same page
// by the next one. A ray going down the tree then changes page less often
// than when only siblings share a page. The tree itself, and so every ray's
// path, is unchanged; node 0 stays the root and children still follow their
// parents, but inner siblings are no longer consecutive.
void lay_out_treelets(BvhBuild& bvh, std::uint32_t nodes_per_page);

// Early split clipping: a triangle whose box is much larger than the average
// box is cut in halves of its box (recursively, at most 2^max_depth pieces),
// and each piece of the triangle gets its own tight box. Long thin triangles
// then no longer make every box around them large. Other primitives keep one
// reference with their own box.
BuildRefs split_large_triangles(std::span<const PrimRecord> prims, std::span<const Box3f> bounds, int max_depth);

// Sets lane i of a node to box b (an empty Box3f makes the lane unused).
void set_lane_box(BvhNode& node, int lane, const Box3f& b);
// Lane i's box (empty for an unused lane): the inverse of set_lane_box.
Box3f lane_box(const BvhNode& node, int lane);
// Whether lane i leads to an inner node (rather than to primitives, or nowhere).
inline bool is_inner_lane(const BvhNode& node, int lane) { return node.count[lane] == 0 && node.child[lane] != 0; }

}  // namespace tracer
