// Binned SAH BVH builder (16 bins on each axis of the centroid box). A set of
// at most four triangles always becomes one leaf: traversal tests such a leaf
// in one four-wide step, so splitting it further only adds nodes to visit.
//
// Parallel build: a node of at least `large_node` references computes its
// bounds, its bins and its partition in chunks of `chunk` references, which
// the caller and helper threads share; per-chunk boxes and counts are merged
// in chunk order. Box3f::extend keeps, on a tie, the later value, so merging
// chunk results in order gives the bits of one pass over all references, and
// the stable partition is unique: every node is what the sequential build
// makes of it. Below a large node, its left subtree may be built on a thread
// of its own into a separate segment of binary nodes; the collapse to
// four-wide nodes walks the binary tree by structure alone, so where a
// binary node is stored never reaches the output. Threads only decide who
// computes what: the tree is the same for every thread count.
#include "tracer/bvh.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "tracer/parallel.hpp"

namespace tracer {
namespace {

constexpr int kBins = 16;
constexpr float kTraversalCost = 1.0f;  // relative to one primitive test
constexpr std::uint32_t kLeafLanes = 4;  // triangles a leaf test handles in one step

// A binary node's address: the segment it is stored in (high 32 bits) and its index there.
using NodeRef = std::uint64_t;
NodeRef make_ref(std::uint32_t segment, std::uint32_t index) { return (NodeRef{segment} << 32) | index; }

// A node of the binary tree before it is collapsed to four-wide nodes.
struct BinNode {
  Box3f box;
  NodeRef left = 0, right = 0;         // inner node: its children
  std::uint32_t first = 0, count = 0;  // leaf (count > 0): primitives in order
};

struct Split {
  int axis = -1;
  int bin = 0;  // primitives with bin index < bin go left
  float cost = 0;
};

// Bins of all three axes, for one chunk or merged over a node.
struct Bins {
  std::array<std::array<Box3f, kBins>, 3> box{};
  std::array<std::array<std::uint32_t, kBins>, 3> count{};
};

// Slots for the threads that may run at once, the caller's included: a
// thread that runs build work holds one; one waiting to join gives it back.
class ThreadBudget {
 public:
  explicit ThreadBudget(unsigned threads) : free_(threads > 1 ? threads - 1 : 0) {}
  bool try_take() {
    std::lock_guard lock(mutex_);
    if (free_ == 0) return false;
    --free_;
    return true;
  }
  void take() {
    std::unique_lock lock(mutex_);
    freed_.wait(lock, [&] { return free_ > 0; });
    --free_;
  }
  void give() {
    {
      std::lock_guard lock(mutex_);
      ++free_;
    }
    freed_.notify_one();
  }

 private:
  std::mutex mutex_;
  std::condition_variable freed_;
  unsigned free_;  // slots not held (the caller holds one from the start)
};

class Builder {
 public:
  Builder(std::span<const Box3f> bounds, const std::vector<bool>& triangle, int max_leaf, const BvhParallelism& par)
      : bounds_(bounds),
        triangle_(triangle),
        max_leaf_(std::max(1, max_leaf)),
        large_node_(std::max<std::uint32_t>(par.large_node, 2)),
        chunk_(std::max<std::uint32_t>(par.chunk, 1)),
        budget_(par.threads) {
    out_.order.resize(bounds.size());
    for (std::uint32_t i = 0; i < bounds.size(); ++i) out_.order[i] = i;
  }

  BvhBuild run() {
    out_.nodes.emplace_back();
    for (int lane = 0; lane < 4; ++lane) set_lane_box(out_.nodes[0], lane, Box3f{});
    if (bounds_.empty()) return std::move(out_);
    const auto n = static_cast<std::uint32_t>(bounds_.size());
    segments_.emplace_back().grow(1);
    if (n >= large_node_) scratch_.resize(n);
    build(segments_[0], 0, 0, 0, n);
    BigVector<std::uint32_t>().swap(scratch_);
    // Four-wide nodes: at most one for each inner binary node, and an inner
    // node has two children, so a tree of T nodes has (T - 1) / 2 of them.
    // Reserved, they are never moved (which would leave a copy behind).
    std::size_t binary = 0;
    for (const Segment& seg : segments_) binary += seg.size();
    out_.nodes.reserve(1 + (binary - 1) / 2);
    const BinNode& root = segments_[0][0];
    if (root.count > 0) {  // one leaf: a root with a single used lane
      set_lane_box(out_.nodes[0], 0, root.box);
      out_.nodes[0].child[0] = root.first;
      out_.nodes[0].count[0] = root.count;
    } else {
      collapse(0, 0, 1);
    }
    return std::move(out_);
  }

 private:
  // Binary nodes in blocks of 2^16 that never move as the segment grows:
  // growing leaves no copy behind, and maps at most one block beyond the nodes.
  class Segment {
   public:
    BinNode& operator[](std::size_t i) { return blocks_[i >> kShift][i & kMask]; }
    const BinNode& operator[](std::size_t i) const { return blocks_[i >> kShift][i & kMask]; }
    std::size_t size() const { return size_; }
    void grow(std::size_t n) {  // appends n nodes
      size_ += n;
      while (blocks_.size() << kShift < size_) blocks_.push_back(std::make_unique<BinNode[]>(std::size_t{1} << kShift));
    }

   private:
    static constexpr unsigned kShift = 16;
    static constexpr std::size_t kMask = (std::size_t{1} << kShift) - 1;
    std::vector<std::unique_ptr<BinNode[]>> blocks_;
    std::size_t size_ = 0;
  };

  const BinNode& node(NodeRef ref) const { return segments_[ref >> 32][ref & 0xffffffffu]; }

  // Builds the binary subtree of primitives [begin, end) into seg[index];
  // `segment` is seg's number. Only this thread touches seg until it returns.
  void build(Segment& seg, std::uint32_t segment, std::uint32_t index, std::uint32_t begin, std::uint32_t end) {
    const std::uint32_t n = end - begin;
    const bool large = n >= large_node_;
    Box3f box, centroids;
    if (large) {
      chunked_bounds(begin, end, box, centroids);
    } else {
      for (std::uint32_t k = begin; k < end; ++k) {
        box.extend(bounds_[out_.order[k]]);
        centroids.extend(bounds_[out_.order[k]].centre());
      }
    }
    seg[index].box = box;
    const Split split = large ? chunked_split(begin, end, centroids, box) : find_split(begin, end, centroids, box);
    if (n <= static_cast<std::uint32_t>(max_leaf_) &&
        (split.axis < 0 || split.cost >= static_cast<float>(n) || one_step_leaf(begin, end))) {
      seg[index].first = begin;
      seg[index].count = n;
      return;
    }
    const std::uint32_t mid =
        large ? chunked_partition(begin, end, centroids, split) : partition(begin, end, centroids, split);
    if (large && std::min(mid - begin, end - mid) >= chunk_ && budget_.try_take()) {
      fork_left(seg, segment, index, begin, mid, end);
      return;
    }
    const auto left = static_cast<std::uint32_t>(seg.size());
    seg.grow(2);
    seg[index].left = make_ref(segment, left);
    seg[index].right = make_ref(segment, left + 1);
    build(seg, segment, left, begin, mid);
    build(seg, segment, left + 1, mid, end);
  }

  // Builds [begin, mid) on a new thread, into a new segment, holding the
  // slot the caller took, and [mid, end) here; returns once both are built,
  // rethrowing what either threw.
  void fork_left(Segment& seg, std::uint32_t segment, std::uint32_t index, std::uint32_t begin, std::uint32_t mid,
                 std::uint32_t end) {
    Segment* left_seg = nullptr;
    std::uint32_t left_segment = 0;
    {
      std::lock_guard lock(segments_mutex_);
      left_segment = static_cast<std::uint32_t>(segments_.size());
      left_seg = &segments_.emplace_back();  // deque: earlier segments stay where they are
      left_seg->grow(1);
    }
    const auto right = static_cast<std::uint32_t>(seg.size());
    seg.grow(1);
    seg[index].left = make_ref(left_segment, 0);
    seg[index].right = make_ref(segment, right);
    std::exception_ptr left_error;
    std::thread thread;
    try {
      thread = std::thread([&, left_seg, left_segment] {
        try {
          build(*left_seg, left_segment, 0, begin, mid);
        } catch (...) {
          left_error = std::current_exception();
        }
        budget_.give();
      });
    } catch (...) {  // no thread to be had: build both here
      budget_.give();
      build(*left_seg, left_segment, 0, begin, mid);
    }
    std::exception_ptr right_error;
    try {
      build(seg, segment, right, mid, end);
    } catch (...) {
      right_error = std::current_exception();
    }
    if (thread.joinable()) {
      budget_.give();  // waiting is not working: another thread may run meanwhile
      thread.join();
      budget_.take();
    }
    if (left_error) std::rethrow_exception(left_error);
    if (right_error) std::rethrow_exception(right_error);
  }

  // Runs work(c) for chunks c = 0..chunks-1 on this thread and on the helper
  // threads the budget allows (about four chunks each at least), whose slots
  // it holds until every chunk is done; rethrows the first exception caught.
  template <class Work>
  void for_chunks(std::uint32_t chunks, const Work& work) {
    unsigned helpers = 0;
    while (helpers + 1 < chunks / 4 && budget_.try_take()) ++helpers;
    try {
      parallel_pieces(helpers + 1, chunks, [&](std::size_t c) { work(static_cast<std::uint32_t>(c)); });
    } catch (...) {
      for (unsigned h = 0; h < helpers; ++h) budget_.give();
      throw;
    }
    for (unsigned h = 0; h < helpers; ++h) budget_.give();
  }

  std::uint32_t chunk_count(std::uint32_t begin, std::uint32_t end) const {
    return (end - begin + chunk_ - 1) / chunk_;
  }
  std::uint32_t chunk_end(std::uint32_t first, std::uint32_t end) const {
    return end - first > chunk_ ? first + chunk_ : end;
  }

  void chunked_bounds(std::uint32_t begin, std::uint32_t end, Box3f& box, Box3f& centroids) {
    std::vector<std::pair<Box3f, Box3f>> part(chunk_count(begin, end));
    for_chunks(static_cast<std::uint32_t>(part.size()), [&](std::uint32_t c) {
      const std::uint32_t first = begin + c * chunk_, last = chunk_end(first, end);
      for (std::uint32_t k = first; k < last; ++k) {
        part[c].first.extend(bounds_[out_.order[k]]);
        part[c].second.extend(bounds_[out_.order[k]].centre());
      }
    });
    for (const auto& [b, cb] : part) {
      box.extend(b);
      centroids.extend(cb);
    }
  }

  Split chunked_split(std::uint32_t begin, std::uint32_t end, const Box3f& centroids, const Box3f& parent) {
    std::vector<Bins> part(chunk_count(begin, end));
    for_chunks(static_cast<std::uint32_t>(part.size()), [&](std::uint32_t c) {
      const std::uint32_t first = begin + c * chunk_, last = chunk_end(first, end);
      for (int axis = 0; axis < 3; ++axis) {
        if (!(centroids.hi[axis] > centroids.lo[axis])) continue;
        for (std::uint32_t k = first; k < last; ++k) {
          const int b = bin_of(out_.order[k], axis, centroids);
          part[c].box[axis][b].extend(bounds_[out_.order[k]]);
          ++part[c].count[axis][b];
        }
      }
    });
    Bins all;
    for (const Bins& p : part)
      for (int axis = 0; axis < 3; ++axis)
        for (int b = 0; b < kBins; ++b) {
          all.box[axis][b].extend(p.box[axis][b]);
          all.count[axis][b] += p.count[axis][b];
        }
    Split best{-1, 0, 1e30f};
    const float parent_area = std::max(parent.half_area(), 1e-30f);
    for (int axis = 0; axis < 3; ++axis)
      if (centroids.hi[axis] > centroids.lo[axis])
        evaluate_axis(axis, all.box[axis], all.count[axis], parent_area, best);
    return best;
  }

  // The stable partition of partition(), chunk by chunk: each chunk's left
  // and right references go to offsets given by the counts of the chunks before it.
  std::uint32_t chunked_partition(std::uint32_t begin, std::uint32_t end, const Box3f& centroids, const Split& split) {
    if (split.axis < 0) return begin + (end - begin) / 2;
    const auto goes_left = [&](std::uint32_t prim) { return bin_of(prim, split.axis, centroids) < split.bin; };
    const std::uint32_t chunks = chunk_count(begin, end);
    std::vector<std::uint32_t> lefts(chunks + 1, 0);  // lefts[c + 1]: left references in chunk c
    for_chunks(chunks, [&](std::uint32_t c) {
      const std::uint32_t first = begin + c * chunk_, last = chunk_end(first, end);
      lefts[c + 1] =
          static_cast<std::uint32_t>(std::count_if(out_.order.begin() + first, out_.order.begin() + last, goes_left));
    });
    for (std::uint32_t c = 0; c < chunks; ++c) lefts[c + 1] += lefts[c];
    const std::uint32_t left_total = lefts[chunks];
    // The references move through [begin, end) of the scratch array, which
    // no other node being partitioned at the same time overlaps.
    std::uint32_t* const moved = scratch_.data() + begin;
    for_chunks(chunks, [&](std::uint32_t c) {
      const std::uint32_t first = begin + c * chunk_, last = chunk_end(first, end);
      std::uint32_t l = lefts[c], r = left_total + (first - begin) - lefts[c];
      for (std::uint32_t k = first; k < last; ++k) {
        const std::uint32_t prim = out_.order[k];
        moved[goes_left(prim) ? l++ : r++] = prim;
      }
    });
    for_chunks(chunks, [&](std::uint32_t c) {
      const std::uint32_t first = c * chunk_, last = chunk_end(first, end - begin);
      std::copy(moved + first, moved + last, out_.order.begin() + begin + first);
    });
    return begin + left_total;
  }

  // Whether primitives [begin, end) are triangles few enough for one four-wide leaf test.
  bool one_step_leaf(std::uint32_t begin, std::uint32_t end) const {
    if (end - begin > kLeafLanes) return false;
    for (std::uint32_t k = begin; k < end; ++k)
      if (!triangle_[out_.order[k]]) return false;
    return true;
  }

  // The binary nodes that become the lanes of the four-wide node for `index`:
  // its children, with the largest inner ones opened until there are four.
  std::vector<NodeRef> lanes_of(NodeRef ref) const {
    std::vector<NodeRef> lanes = {node(ref).left, node(ref).right};
    while (lanes.size() < 4) {
      int pick = -1;
      for (int i = 0; i < static_cast<int>(lanes.size()); ++i)
        if (node(lanes[i]).count == 0 &&
            (pick < 0 || node(lanes[i]).box.half_area() > node(lanes[pick]).box.half_area()))
          pick = i;
      if (pick < 0) break;
      const BinNode opened = node(lanes[pick]);
      lanes[pick] = opened.left;
      lanes.insert(lanes.begin() + pick + 1, opened.right);
    }
    return lanes;
  }

  // Fills four-wide node `slot` from inner binary node `ref`. The inner
  // children of a node get consecutive slots, so siblings share cache lines
  // and pages.
  void collapse(std::uint32_t slot, NodeRef ref, std::uint32_t depth) {
    out_.depth = std::max(out_.depth, depth);
    const std::vector<NodeRef> lanes = lanes_of(ref);
    std::vector<std::pair<std::uint32_t, NodeRef>> inner;  // (slot, binary node)
    auto next = static_cast<std::uint32_t>(out_.nodes.size());
    for (int lane = 0; lane < 4; ++lane) {
      const bool used = lane < static_cast<int>(lanes.size());
      set_lane_box(out_.nodes[slot], lane, used ? node(lanes[lane]).box : Box3f{});
      if (!used) continue;
      const BinNode& b = node(lanes[lane]);
      out_.nodes[slot].count[lane] = b.count;
      out_.nodes[slot].child[lane] = b.count > 0 ? b.first : next;
      if (b.count == 0) inner.emplace_back(next++, lanes[lane]);
    }
    out_.nodes.resize(next);
    for (const auto& [child_slot, child] : inner) collapse(child_slot, child, depth + 1);
  }

  int bin_of(std::uint32_t prim, int axis, const Box3f& centroids) const {
    const float lo = centroids.lo[axis], ext = centroids.hi[axis] - lo;
    const float c = bounds_[prim].centre()[axis];
    return clamped_int((c - lo) / ext * kBins, 0, kBins - 1);
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

  std::span<const Box3f> bounds_;
  const std::vector<bool>& triangle_;
  int max_leaf_;
  std::uint32_t large_node_, chunk_;
  ThreadBudget budget_;
  std::mutex segments_mutex_;     // guards segments_ while threads add to it
  std::deque<Segment> segments_;  // the binary tree; segments_[0][0] is its root
  BigVector<std::uint32_t> scratch_;  // chunked_partition's, one slot a reference (large builds)
  BvhBuild out_;
};

}  // namespace

void set_lane_box(BvhNode& node, int lane, const Box3f& b) {
  for (int a = 0; a < 3; ++a) {
    node.lo[a][lane] = b.lo[a];
    node.hi[a][lane] = b.hi[a];
  }
  if (b.empty()) node.child[lane] = node.count[lane] = 0;
}

Box3f lane_box(const BvhNode& node, int lane) {
  Box3f b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = node.lo[a][lane];
    b.hi[a] = node.hi[a][lane];
  }
  return b;
}

BvhBuild build_bvh(const BuildRefs& refs, int max_leaf, const BvhParallelism& parallelism) {
  return Builder(refs.bounds, refs.triangle, max_leaf, parallelism).run();
}

namespace {

// Half the surface area of the box around a node's lanes: how likely a ray
// that reaches its parent is to visit it.
float node_area(const BvhNode& node) {
  Box3f box;
  for (int lane = 0; lane < 4; ++lane) {
    const Box3f b = lane_box(node, lane);
    if (!b.empty()) box.extend(b);
  }
  return box.empty() ? 0.0f : box.half_area();
}

}  // namespace

void lay_out_treelets(BvhBuild& bvh, std::uint32_t nodes_per_page) {
  const auto n = static_cast<std::uint32_t>(bvh.nodes.size());
  if (nodes_per_page < 2 || n <= 1) return;
  std::vector<float> area(n);
  for (std::uint32_t i = 0; i < n; ++i) area[i] = node_area(bvh.nodes[i]);
  // Heap order: largest area on top, ties to the lower old index, so the layout is deterministic.
  const auto below = [&](std::uint32_t a, std::uint32_t b) { return area[a] != area[b] ? area[a] < area[b] : a > b; };
  std::vector<std::uint32_t> placed;  // old indices in their new order
  placed.reserve(n);
  std::deque<std::uint32_t> roots{0};  // treelets still to lay out, in the order they were cut off
  std::vector<std::uint32_t> frontier;  // heap of the current treelet's candidates
  while (!roots.empty() || !frontier.empty()) {
    if (frontier.empty()) {  // the treelet is whole but its page has room: the next one goes on
      frontier.push_back(roots.front());
      roots.pop_front();
    }
    std::pop_heap(frontier.begin(), frontier.end(), below);
    const std::uint32_t k = frontier.back();
    frontier.pop_back();
    placed.push_back(k);
    for (int lane = 0; lane < 4; ++lane)
      if (is_inner_lane(bvh.nodes[k], lane)) {
        frontier.push_back(bvh.nodes[k].child[lane]);
        std::push_heap(frontier.begin(), frontier.end(), below);
      }
    if (placed.size() % nodes_per_page == 0) {  // page full: the candidates left out root treelets of their own
      std::sort_heap(frontier.begin(), frontier.end(), below);
      roots.insert(roots.end(), frontier.rbegin(), frontier.rend());
      frontier.clear();
    }
  }
  std::vector<std::uint32_t> new_index(n);
  for (std::uint32_t i = 0; i < n; ++i) new_index[placed[i]] = i;
  BigVector<BvhNode> nodes(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    nodes[i] = bvh.nodes[placed[i]];
    for (int lane = 0; lane < 4; ++lane)
      if (is_inner_lane(nodes[i], lane)) nodes[i].child[lane] = new_index[nodes[i].child[lane]];
  }
  bvh.nodes = std::move(nodes);
}

namespace {

using Piece = std::vector<Vec3f>;  // a convex polygon, part of a triangle

// Splits a convex polygon by the plane coord[axis] = pos into its two sides.
void clip(const Piece& poly, int axis, float pos, Piece& below, Piece& above) {
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec3f& a = poly[i];
    const Vec3f& b = poly[(i + 1) % poly.size()];
    const float da = a[axis] - pos, db = b[axis] - pos;
    if (da <= 0) below.push_back(a);
    if (da >= 0) above.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      Vec3f x = a + (b - a) * (da / (da - db));
      x[axis] = pos;
      below.push_back(x);
      above.push_back(x);
    }
  }
}

Box3f piece_bounds(const Piece& poly, const Box3f& within) {
  Box3f b;
  for (const Vec3f& p : poly) b.extend(p);
  b.lo = max(b.lo, within.lo);
  b.hi = min(b.hi, within.hi);
  return widened(b, 2e-6f);  // float rounding in the clipped vertices
}

void split_piece(const Piece& poly, const Box3f& box, float max_area, int depth,
                 std::uint32_t prim, BuildRefs& out) {
  if (depth == 0 || box.half_area() <= max_area) {
    out.bounds.push_back(box);
    out.prim.push_back(prim);
    out.triangle.push_back(true);
    return;
  }
  const Vec3f e = box.extent();
  const int axis = e.x > e.y ? (e.x > e.z ? 0 : 2) : (e.y > e.z ? 1 : 2);
  const float pos = (box.lo[axis] + box.hi[axis]) * 0.5f;
  Piece below, above;
  clip(poly, axis, pos, below, above);
  Box3f lower = box, upper = box;
  lower.hi[axis] = pos;
  upper.lo[axis] = pos;
  if (below.size() >= 3) split_piece(below, piece_bounds(below, lower), max_area, depth - 1, prim, out);
  if (above.size() >= 3) split_piece(above, piece_bounds(above, upper), max_area, depth - 1, prim, out);
}

}  // namespace

BuildRefs split_large_triangles(std::span<const PrimRecord> prims, std::span<const Box3f> bounds, int max_depth) {
  double total = 0;
  for (const Box3f& b : bounds) total += b.half_area();
  const float max_area = bounds.empty() ? 0.0f : static_cast<float>(2.0 * total / bounds.size());
  BuildRefs out;
  out.bounds.reserve(prims.size());  // most primitives keep one reference
  out.prim.reserve(prims.size());
  out.triangle.reserve(prims.size());
  for (std::uint32_t i = 0; i < prims.size(); ++i) {
    const PrimRecord& p = prims[i];
    const bool triangle =
        p.kind == PrimKind::flat_triangle || p.kind == PrimKind::smooth_triangle;
    if (!triangle || bounds[i].half_area() <= max_area) {
      out.bounds.push_back(bounds[i]);
      out.prim.push_back(i);
      out.triangle.push_back(triangle);
      continue;
    }
    split_piece({p.p0, p.p0 + p.p1, p.p0 + p.p2}, bounds[i], max_area, max_depth, i, out);
  }
  return out;
}

}  // namespace tracer
