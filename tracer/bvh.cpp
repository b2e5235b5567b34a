// Binned SAH BVH builder (16 bins on each axis of the centroid box).
#include "tracer/bvh.hpp"

#include <algorithm>
#include <array>

namespace tracer {
namespace {

constexpr int kBins = 16;
constexpr float kTraversalCost = 1.0f;  // relative to one primitive test

// A built subtree as its parent sees it: a box and a leaf or node reference.
struct ChildRef {
  Box3f box;
  std::uint32_t child = 0;
  std::uint32_t count = 0;
};

struct Split {
  int axis = -1;
  int bin = 0;  // primitives with bin index < bin go left
  float cost = 0;
};

class Builder {
 public:
  Builder(const std::vector<Box3f>& bounds, int max_leaf)
      : bounds_(bounds), max_leaf_(std::max(1, max_leaf)) {
    out_.order.resize(bounds.size());
    for (std::uint32_t i = 0; i < bounds.size(); ++i) out_.order[i] = i;
  }

  BvhBuild run() {
    if (bounds_.empty()) {
      out_.nodes.push_back(BvhNode{});  // never traversed: the tracer checks for no primitives
      return std::move(out_);
    }
    const ChildRef top = build(0, static_cast<std::uint32_t>(bounds_.size()), 1);
    if (top.count > 0) {
      // A single leaf: the root's two children split it (or repeat a lone
      // primitive), since traversal has no notion of an absent child.
      const std::uint32_t half = std::max(1u, top.count / 2);
      BvhNode root{};
      root.box[0] = root.box[1] = top.box;
      root.child[0] = top.child;
      root.count[0] = half;
      root.child[1] = top.count > 1 ? top.child + half : top.child;
      root.count[1] = top.count > 1 ? top.count - half : top.count;
      out_.nodes.push_back(root);
    }
    return std::move(out_);
  }

 private:
  ChildRef build(std::uint32_t begin, std::uint32_t end, std::uint32_t depth) {
    Box3f box, centroids;
    for (std::uint32_t k = begin; k < end; ++k) {
      box.extend(bounds_[out_.order[k]]);
      centroids.extend(bounds_[out_.order[k]].centre());
    }
    const std::uint32_t n = end - begin;
    const Split split = find_split(begin, end, centroids, box);
    const float leaf_cost = static_cast<float>(n);
    if (n <= static_cast<std::uint32_t>(max_leaf_) && (split.axis < 0 || split.cost >= leaf_cost))
      return {box, begin, n};
    const std::uint32_t mid = partition(begin, end, centroids, split);
    const auto index = static_cast<std::uint32_t>(out_.nodes.size());
    out_.nodes.emplace_back();
    out_.depth = std::max(out_.depth, depth);
    const ChildRef left = build(begin, mid, depth + 1);
    const ChildRef right = build(mid, end, depth + 1);
    BvhNode& node = out_.nodes[index];
    node.box[0] = left.box;
    node.box[1] = right.box;
    node.child[0] = left.child;
    node.child[1] = right.child;
    node.count[0] = left.count;
    node.count[1] = right.count;
    return {box, index, 0};
  }

  int bin_of(std::uint32_t prim, int axis, const Box3f& centroids) const {
    const float lo = centroids.lo[axis], ext = centroids.hi[axis] - lo;
    const float c = bounds_[prim].centre()[axis];
    const int b = static_cast<int>((c - lo) / ext * kBins);
    return std::clamp(b, 0, kBins - 1);
  }

  Split find_split(std::uint32_t begin, std::uint32_t end, const Box3f& centroids,
                   const Box3f& parent) const {
    Split best{-1, 0, 1e30f};
    const float parent_area = std::max(parent.half_area(), 1e-30f);
    for (int axis = 0; axis < 3; ++axis) {
      if (!(centroids.hi[axis] > centroids.lo[axis])) continue;
      std::array<Box3f, kBins> bin_box{};
      std::array<std::uint32_t, kBins> bin_count{};
      for (std::uint32_t k = begin; k < end; ++k) {
        const int b = bin_of(out_.order[k], axis, centroids);
        bin_box[b].extend(bounds_[out_.order[k]]);
        ++bin_count[b];
      }
      evaluate_axis(axis, bin_box, bin_count, parent_area, best);
    }
    return best;
  }

  static void evaluate_axis(int axis, const std::array<Box3f, kBins>& bin_box,
                            const std::array<std::uint32_t, kBins>& bin_count,
                            float parent_area, Split& best) {
    // Sweep from the right to get the area and count of every right-hand side.
    std::array<float, kBins> right_area{};
    std::array<std::uint32_t, kBins> right_count{};
    Box3f acc;
    std::uint32_t cnt = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.extend(bin_box[b]);
      cnt += bin_count[b];
      right_area[b] = acc.half_area();
      right_count[b] = cnt;
    }
    Box3f left;
    std::uint32_t left_count = 0;
    for (int b = 1; b < kBins; ++b) {
      left.extend(bin_box[b - 1]);
      left_count += bin_count[b - 1];
      if (left_count == 0 || right_count[b] == 0) continue;
      const float cost = kTraversalCost + (left.half_area() * static_cast<float>(left_count) +
                                           right_area[b] * static_cast<float>(right_count[b])) /
                                              parent_area;
      if (cost < best.cost) best = {axis, b, cost};
    }
  }

  std::uint32_t partition(std::uint32_t begin, std::uint32_t end, const Box3f& centroids,
                          const Split& split) {
    auto first = out_.order.begin() + begin, last = out_.order.begin() + end;
    if (split.axis < 0) return begin + (end - begin) / 2;  // coincident centroids: halve
    auto mid = std::stable_partition(first, last, [&](std::uint32_t prim) {
      return bin_of(prim, split.axis, centroids) < split.bin;
    });
    return static_cast<std::uint32_t>(mid - out_.order.begin());
  }

  const std::vector<Box3f>& bounds_;
  int max_leaf_;
  BvhBuild out_;
};

}  // namespace

BvhBuild build_bvh(const std::vector<Box3f>& prim_bounds, int max_leaf) {
  return Builder(prim_bounds, max_leaf).run();
}

}  // namespace tracer
