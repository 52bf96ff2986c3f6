// Node pass: which binary inner nodes become wide nodes and which are opened
// into their wide parent's slots is chosen by dynamic programming over the
// build tree (Ylitie, Karras & Laine, "Efficient Incoherent Ray Traversal on
// GPUs Through Compressed Wide BVHs", HPG 2017, Sec. 4.1, with the leaves
// kept as built): cost(n, i) = the least total surface area of the wide nodes
// needed to cover subtree n with at most i slots, where a wide node's cost is
// its area. Opening by largest area alone (Embree's greedy collapse) left
// 2-3 children in most bottom nodes of our SAH trees (leaves of 1-2
// triangles): on a 1M-triangle torus 229k bvh8 nodes against 108k here.
// The slots of every opened binary node are contiguous (its left forest, then
// its right), so CollapsedInner records them as ranges. A wide node's inner
// children get consecutive indices when it is filled, depth first. Slots
// still free then take parts of the node's leaves (split_leaves_into_free_slots).
// The plan is solved in parallel over subtrees (CollapsePlan), the walk that
// numbers the wide nodes runs on one thread, and the nodes are then filled in
// parallel from the slots it chose, so the layout is thread-count independent.
// Triangle pass: gather_leaf_triangles, as for the binary layout. The two
// passes only read the build tree, the prim info and the scene, so a caller
// may run them concurrently (flatten_wide_nodes, then set `triangles`).
#include "bvh/layout/flatten_wide.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "bvh/layout/flatten_bvh2.h"
#include "bvh/memory/build_array.h"
#include "bvh/memory/prefault.h"

namespace hprt {
namespace {

// The collapse plan: per binary inner node n and slot budget i (1..N), the
// least cost and how it is reached: left_slots = 0 means n takes one slot
// itself (a wide node of its own), k > 0 that n is opened and its left
// child's forest gets k slots, the right child's i - k. With one slot n is
// always a slot of its own, so entry i = 1 holds instead how the N slots of
// the wide node made from n split between its children (root_left_slots):
// the walk then reads no costs. A leaf always takes one slot at no cost;
// its entries are never written nor read.
template <int N>
struct CollapsePlan {
  const BuildTree& tree;
  BuildArray<float> cost;          // [n * N + i - 1]
  BuildArray<uint8_t> left_slots;  // [n * N + i - 1]

  const float* costs_of(uint32_t b) const {
    static constexpr float kLeaf[N] = {};
    return tree.nodes[b].is_leaf() ? kLeaf : &cost[size_t(b) * N];
  }
  int left_slots_of(uint32_t b, int i) const {
    return i == 1 || tree.nodes[b].is_leaf() ? 0 : left_slots[size_t(b) * N + i - 1];
  }

  // The build tree is in preorder (build_tree.h): subtree b is the index
  // range [b, end), its left child's [b + 1, right), its right child's
  // [right, end). The subtrees below a cut near the root are solved in
  // parallel, each by one pass in reverse index order (every child before
  // its parent); then the few nodes above the cut. A node whose children
  // leave its range is a malformed tree.
  explicit CollapsePlan(const BuildTree& t)
      : tree(t), cost(t.nodes.size() * N), left_slots(t.nodes.size() * N) {
    std::vector<std::pair<uint32_t, uint32_t>> below;  // subtree ranges
    std::vector<uint32_t> above;                       // in preorder
    cut(0, uint32_t(tree.nodes.size()), 0, below, above);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, below.size(), 1),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t s = r.begin(); s != r.end(); ++s)
                          for (uint32_t b = below[s].second; b-- > below[s].first;)
                            solve(b, below[s].second);
                      });
    for (size_t a = above.size(); a-- > 0;) solve(above[a], uint32_t(tree.nodes.size()));
  }

  static constexpr int kCutDepth = 6;            // up to 64 subtrees
  static constexpr uint32_t kMinSubtree = 4096;  // nodes: smaller ones are not cut

  void cut(uint32_t b, uint32_t end, int depth, std::vector<std::pair<uint32_t, uint32_t>>& below,
           std::vector<uint32_t>& above) const {
    const BuildNode& node = tree.nodes[b];
    if (node.is_leaf() || depth == kCutDepth || end - b < kMinSubtree) {
      below.emplace_back(b, end);
      return;
    }
    if (node.right <= b + 1 || node.right >= end)
      throw std::invalid_argument("flatten: malformed build tree");
    above.push_back(b);
    cut(b + 1, node.right, depth + 1, below, above);
    cut(node.right, end, depth + 1, below, above);
  }

  // Node b's entries from its children's; its subtree ends before `end`.
  void solve(size_t b, uint32_t end) {
    const BuildNode& node = tree.nodes[b];
    if (node.is_leaf()) return;
    if (node.right <= b + 1 || node.right >= end)
      throw std::invalid_argument("flatten: malformed build tree");
    float* c = &cost[b * N];
    uint8_t* k = &left_slots[b * N];
    c[0] = node.bounds.half_area();
    if (tree.nodes[b + 1].is_leaf() && tree.nodes[node.right].is_leaf()) {
      // Two leaves: a wide node of its own costs its area, opening nothing.
      for (int i = 1; i <= N; ++i) {
        if (i > 1) c[i - 1] = 0.0f;
        k[i - 1] = 1;
      }
      return;
    }
    const float* l = costs_of(uint32_t(b + 1));
    const float* r = costs_of(node.right);
    // open[i - 1]: n opened, its children sharing at most i slots (i >= 2).
    float open[N];
    uint8_t open_k[N];
    for (int i = 2; i <= N; ++i) {
      open[i - 1] = l[0] + r[i - 2];
      open_k[i - 1] = 1;
      for (int j = 2; j < i; ++j) {
        const float v = l[j - 1] + r[i - j - 1];
        if (v < open[i - 1]) {
          open[i - 1] = v;
          open_k[i - 1] = uint8_t(j);
        }
      }
    }
    // As a wide node of its own, n costs its area plus its best N-slot
    // forest; with more slots the plan opens n where that is cheaper.
    c[0] += open[N - 1];
    k[0] = open_k[N - 1];
    for (int i = 2; i <= N; ++i) {
      const bool opened = open[i - 1] < c[0];
      c[i - 1] = opened ? open[i - 1] : c[0];
      k[i - 1] = opened ? open_k[i - 1] : 0;
    }
  }

  // How the N slots of the wide node made from inner node b split between
  // its children: the lowest k of the least l[k - 1] + r[N - k - 1], as
  // solve found it.
  int root_left_slots(uint32_t b) const { return left_slots[size_t(b) * N]; }
};

struct Filler {
  const BuildTree& tree;
  size_t visited = 0;  // binary nodes placed (wide roots, opened, leaves)

  // Counts a placed node; a node reached twice (a DAG, not a tree) is caught
  // here before the walk can grow past the tree's size.
  void place() {
    if (++visited > tree.nodes.size())
      throw std::invalid_argument("flatten: build tree is not a single binary tree");
  }

  NodeRef leaf_ref(uint32_t b) {
    const BuildNode& bn = tree.nodes[b];
    if (size_t(bn.first) + bn.count > tree.prim_order.size())
      throw std::invalid_argument("flatten: leaf range past prim_order");
    if (bn.count > NodeRef::kMaxLeafCount)
      throw std::invalid_argument("flatten: a leaf of more than 255 triangles");
    place();
    return NodeRef::leaf(bn.first, bn.count);
  }
};

// Appends the slots of subtree b given at most i of them, recording each
// opened node's slot range.
template <int N>
void expand(const CollapsePlan<N>& plan, const BuildTree& tree, Filler& f, uint32_t b, int i,
            uint32_t* slot, int& k, CollapsedInner<N>& col) {
  const int left = plan.left_slots_of(b, i);
  if (left == 0) {
    slot[k++] = b;
    return;
  }
  f.place();
  const int begin = k;
  expand(plan, tree, f, b + 1, left, slot, k, col);
  expand(plan, tree, f, tree.nodes[b].right, i - left, slot, k, col);
  col.begin[col.count] = uint8_t(begin);
  col.end[col.count] = uint8_t(k);
  ++col.count;
}

// Slots the collapse left free (k < N) take parts of the node's leaves: the
// leaf with the most triangles (the first of them on a tie) is halved in
// leaf order, its parts in adjacent slots, until the slots are full or every
// leaf holds one triangle. A slot box test is far cheaper than a triangle
// test, and Morton leaves are not chosen by SAH: leaves of up to
// max_leaf_size all over (SAH trees barely change). The
// binary tree's leaves are recorded as slot ranges, so its SAH cost can
// still be computed from the layout; each part keeps the verts block of its
// binary leaf (NodeRef::leaf_part).
template <int N>
void split_leaves_into_free_slots(WideNode<N>& node, CollapsedInner<N>& col, const BuildTree& tree,
                                  const PrimInfo& prims, const Scene& scene) {
  int k = 0;  // slots in use: the first k
  while (k < N && !node.child[k].empty()) ++k;
  const auto range_box = [&](uint32_t first, uint32_t end) {
    AABB box;
    for (uint32_t j = first; j < end; ++j) box.extend(prims.box(tree.prim_order[j], scene));
    return box;
  };
  while (k < N) {
    int best = -1;
    uint32_t most = 1;
    for (int i = 0; i < k; ++i)
      if (node.child[i].is_leaf() && node.child[i].count() > most) {
        best = i;
        most = node.child[i].count();
      }
    if (best < 0) return;
    for (int i = k; i > best + 1; --i) {
      node.child[i] = node.child[i - 1];
      node.set_box(i, node.box(i - 1));
    }
    ++k;
    const LeafRange whole = node.child[best].leaf_range();
    const uint32_t first = whole.first, half = most / 2;
    node.child[best] = NodeRef::leaf_part(first, half, whole.block_first, whole.block_count);
    node.set_box(best, range_box(first, first + half));
    node.child[best + 1] =
        NodeRef::leaf_part(first + half, most - half, whole.block_first, whole.block_count);
    node.set_box(best + 1, range_box(first + half, first + most));
    // Ranges after the split slot move one on; a range holding it grows.
    const auto shift = [best](uint8_t& begin, uint8_t& end) {
      if (begin > best) ++begin;
      if (end > best) ++end;
    };
    for (int r = 0; r < col.count; ++r) shift(col.begin[r], col.end[r]);
    bool grown = false;
    for (int r = 0; r < col.split_leaves; ++r) {
      grown = grown || (col.leaf_begin[r] <= best && best < col.leaf_end[r]);
      shift(col.leaf_begin[r], col.leaf_end[r]);
    }
    if (!grown) {
      col.leaf_begin[col.split_leaves] = uint8_t(best);
      col.leaf_end[col.split_leaves] = uint8_t(best + 2);
      ++col.split_leaves;
    }
  }
}

// Prefetches for the boxes of the leaves among slot[0, k) that hold more
// than one triangle (those split_leaves_into_free_slots may halve), in two
// stages a few nodes apart: PrimInfo::box reads a box, or once the boxes are
// released a ref and then the scene's triangle (its vertices are the third,
// unprefetched load). Stage 0: the refs (nothing while boxes are held);
// stage 1: the boxes, or the triangles of the refs stage 0 brought in.
// Always inlined: GCC deletes a call whose only effects are prefetches.
template <int kStage>
[[gnu::always_inline]] inline void prefetch_leaf_prim_boxes(const BuildTree& tree,
                                                            const PrimInfo& prims,
                                                            const Scene& scene,
                                                            const uint32_t* slot, int k) {
  const bool held = !prims.bounds.empty();
  if (kStage == 0 && held) return;
  for (int i = 0; i < k; ++i) {
    const BuildNode& c = tree.nodes[slot[i]];
    if (c.count < 2) continue;
    const size_t end = std::min<size_t>(size_t(c.first) + c.count, prims.size());
    for (size_t j = c.first; j < end; ++j) {
      const uint32_t p = tree.prim_order[j];
      const void* at;
      if (held) {
        at = &prims.bounds[p];
      } else if (kStage == 0) {
        at = &prims.refs[p];
      } else {
        const PrimRef r = prims.refs[p];
        at = &scene.meshes[r.geom_id].triangles[r.prim_id];
      }
      _mm_prefetch(static_cast<const char*>(at), _MM_HINT_T0);
    }
  }
}

}  // namespace

template <int N>
WideBvh<N> flatten_wide_nodes(const BuildTree& tree, const PrimInfo& prims, const Scene& scene) {
  WideBvh<N> out;
  const size_t n = tree.nodes.size();
  if (n == 0) return out;
  if (tree.prim_order.size() != prims.size())
    throw std::invalid_argument("flatten: prim_order does not match PrimInfo");

  Filler f{tree};
  out.bounds = tree.nodes[0].bounds;
  // The walk decides each wide node's slots (the build nodes they hold); a
  // wide node's inner children get consecutive indices from first_child on,
  // depth first. The nodes are then filled in parallel.
  struct Shape {
    uint32_t slot[N];
    uint32_t first_child;
    int k;
  };
  std::vector<Shape> shapes;
  if (tree.nodes[0].is_leaf()) {
    out.root = f.leaf_ref(0);
  } else {
    const CollapsePlan<N> plan(tree);
    // A wide node holds at least 2 binary nodes' worth of children, so there
    // are at most (n - 1) / 2 of them: reserve once, no reallocation.
    shapes.reserve((n - 1) / 2 + 1);
    out.collapsed.reserve((n - 1) / 2 + 1);
    shapes.emplace_back();
    out.collapsed.emplace_back();
    out.root = NodeRef::inner(0);
    std::vector<std::pair<uint32_t, uint32_t>> todo;  // (build node, wide node)
    todo.emplace_back(0u, 0u);
    while (!todo.empty()) {
      const auto [b, w] = todo.back();
      todo.pop_back();
      f.place();
      Shape s;
      s.k = 0;
      CollapsedInner<N> col;
      const int left = plan.root_left_slots(b);
      expand(plan, tree, f, b + 1, left, s.slot, s.k, col);
      expand(plan, tree, f, f.tree.nodes[b].right, N - left, s.slot, s.k, col);
      s.first_child = uint32_t(shapes.size());
      const size_t pushed_from = todo.size();
      for (int i = 0; i < s.k; ++i) {
        if (tree.nodes[s.slot[i]].is_leaf()) {
          (void)f.leaf_ref(s.slot[i]);  // checks the leaf, counts it
        } else {
          todo.emplace_back(s.slot[i], uint32_t(shapes.size()));
          shapes.emplace_back();
          out.collapsed.emplace_back();
        }
      }
      // Visit the first child's subtree first (depth first, in slot order).
      std::reverse(todo.begin() + std::ptrdiff_t(pushed_from), todo.end());
      shapes[w] = s;
      out.collapsed[w] = col;
    }
  }
  if (f.visited != n)
    throw std::invalid_argument("flatten: build tree is not a single binary tree");
  out.nodes.reserve(shapes.size());
  prefault_pages(out.nodes.data(), shapes.size() * sizeof(WideNode<N>));
  out.nodes.resize(shapes.size());
  // Each node on its own, in parallel: the part boxes of split leaves are
  // read at random from the prim boxes (or the scene), so their loads are
  // prefetched in two stages, kFillAhead nodes apart (only a node with free
  // slots splits its leaves).
  constexpr size_t kFillAhead = 6;
  const auto prefetch_stage = [&](size_t w, auto stage) {
    const Shape& s = shapes[w];
    if (s.k < N) prefetch_leaf_prim_boxes<decltype(stage)::value>(tree, prims, scene, s.slot, s.k);
  };
  using Stage0 = std::integral_constant<int, 0>;
  using Stage1 = std::integral_constant<int, 1>;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, shapes.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        const auto ahead = [&](size_t stages) {
          return std::min(r.end(), r.begin() + stages * kFillAhead);
        };
        for (size_t w = r.begin(); w != ahead(2); ++w) prefetch_stage(w, Stage0{});
        for (size_t w = r.begin(); w != ahead(1); ++w) prefetch_stage(w, Stage1{});
        for (size_t w = r.begin(); w != r.end(); ++w) {
          if (w + 2 * kFillAhead < r.end()) prefetch_stage(w + 2 * kFillAhead, Stage0{});
          if (w + kFillAhead < r.end()) prefetch_stage(w + kFillAhead, Stage1{});
          const Shape& s = shapes[w];
          WideNode<N>& node = out.nodes[w];
          for (int i = 0; i < N; ++i) node.clear_slot(i);
          uint32_t next_child = s.first_child;
          for (int i = 0; i < s.k; ++i) {
            const BuildNode& c = tree.nodes[s.slot[i]];
            node.set_box(i, c.bounds);
            node.child[i] =
                c.is_leaf() ? NodeRef::leaf(c.first, c.count) : NodeRef::inner(next_child++);
          }
          split_leaves_into_free_slots(node, out.collapsed[w], tree, prims, scene);
        }
      });
  return out;
}

template <int N>
WideBvh<N> flatten_wide(const BuildTree& tree, const PrimInfo& prims, const Scene& scene,
                        TriangleArrays arrays) {
  WideBvh<N> out = flatten_wide_nodes<N>(tree, prims, scene);
  out.triangles = gather_leaf_triangles(tree, prims, scene, arrays);
  return out;
}

template WideBvh<4> flatten_wide_nodes<4>(const BuildTree&, const PrimInfo&, const Scene&);
template WideBvh<8> flatten_wide_nodes<8>(const BuildTree&, const PrimInfo&, const Scene&);
template WideBvh<4> flatten_wide<4>(const BuildTree&, const PrimInfo&, const Scene&,
                                    TriangleArrays);
template WideBvh<8> flatten_wide<8>(const BuildTree&, const PrimInfo&, const Scene&,
                                    TriangleArrays);

}  // namespace hprt
