// hprt's own BVH behind the Intersector interface: prim info -> build tree
// (the builder named in the options, oneTBB inside the caller's task arena)
// -> the traversal layout named in the options (binary, or wide 4/8 collapsed
// from the same tree; node and triangle passes as two tasks)
// and the tree statistics; batches of rays traced in parallel blocks with one
// switch per batch into a fully inlined traversal.
// update(): per BackendOptions::update, a full rebuild, a refit over the last
// build's topology (bvh/refit/refit_bvh2.h), or adaptive (refit, then rebuild when the
// refitted SAH cost exceeds adaptive_factor x the cost at the last rebuild).
#include "backends/bvh_backend.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bvh/builders/builders.h"
#include "bvh/layout/flatten_bvh2.h"
#include "bvh/layout/flatten_wide.h"
#include "bvh/memory/huge_buffer.h"
#include "bvh/refit/refit_bvh2.h"
#include "bvh/refit/refit_wide.h"
#include "bvh/traverse/traverse_bvh2.h"
#include "bvh/traverse/traverse_packet.h"
#include "bvh/traverse/traverse_wide.h"
#include "core/ray_coherence.h"
#include "core/stopwatch.h"

namespace hprt {
namespace {

constexpr size_t kGrain = 128;  // rays per parallel task

template <typename Test, bool kAnyHit>
bool trace_one(const Bvh2& bvh, const Ray& ray, Hit& hit) {
  return traverse<Test, kAnyHit>(bvh, ray, hit);
}
template <typename Test, bool kAnyHit, int N>
bool trace_one(const WideBvh<N>& bvh, const Ray& ray, Hit& hit) {
  return traverse_wide<Test, kAnyHit>(bvh, ray, hit);
}

// Packets need AVX-512 (traverse_packet.h).
#if defined(HPRT_HAS_PACKETS)
constexpr bool kTracesPackets = true;
#else
constexpr bool kTracesPackets = false;
#endif

// How far apart a packet's origins may be: the embree backend's fraction of
// the scene's extent, with the root box in place of the scene's.
inline float packet_origin_tolerance(const AABB& root) {
  return root.empty() ? 0.0f : kCoherentOriginFraction * max_component(root.diagonal());
}
inline float packet_origin_tolerance(const Bvh2& bvh) {
  return bvh.empty() ? 0.0f : packet_origin_tolerance(AABB(bvh.nodes[0].min, bvh.nodes[0].max));
}
template <int N>
float packet_origin_tolerance(const WideBvh<N>& bvh) {
  if (!bvh.root.is_inner()) return 0.0f;
  const WideNode<N>& root = bvh.nodes[bvh.root.index()];
  AABB box;
  for (int i = 0; i < N && !root.child[i].empty(); ++i) box.extend(root.box(i));
  return packet_origin_tolerance(box);
}

// Rays go in fixed groups of kGroup (ray i in group i / kGroup, whatever the
// thread count), as in the embree backend: with AVX-512 (any layout) a full
// group of coherent rays (core/ray_coherence.h) is one packet, with the
// answers its rays get one by one; anything else is traced ray by ray.
// kAnyHit writes `occluded`, otherwise `hits`.
template <typename Test, bool kAnyHit, typename Bvh>
void trace_batch(const Bvh& bvh, std::span<const Ray> rays, Hit* hits, uint8_t* occluded) {
  constexpr size_t kGroup = 16;
  const float tolerance = packet_origin_tolerance(bvh);
  const size_t groups = (rays.size() + kGroup - 1) / kGroup;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, groups, kGrain / kGroup),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t g = range.begin(); g != range.end(); ++g) {
                        const size_t first = g * kGroup;
                        const size_t count = std::min(kGroup, rays.size() - first);
                        const Ray* r = rays.data() + first;
                        if constexpr (kTracesPackets) {
                          static_assert(kGroup == kPacketSize);
                          if (count == kGroup && rays_coherent(r, kGroup, tolerance)) {
                            // Only the array this query writes is offset (the other is null).
                            if constexpr (kAnyHit)
                              traverse_packet<Test, true>(bvh, r, nullptr, occluded + first);
                            else
                              traverse_packet<Test, false>(bvh, r, hits + first, nullptr);
                            continue;
                          }
                        }
                        for (size_t i = first; i < first + count; ++i) {
                          Hit h;
                          const bool found =
                              ray_is_valid(rays[i]) && trace_one<Test, kAnyHit>(bvh, rays[i], h);
                          if constexpr (kAnyHit)
                            occluded[i] = found;
                          else
                            hits[i] = h;
                        }
                      }
                    });
}

class BvhIntersector final : public Intersector {
  // Calls f with the layout in use (options_.layout); Self is const or not.
  template <typename Self, typename F>
  static decltype(auto) with_layout(Self& self, F&& f) {
    switch (self.options_.layout) {
      case BvhLayout::kBvh2:
        return f(self.bvh2_);
      case BvhLayout::kBvh4:
        return f(self.bvh4_);
      case BvhLayout::kBvh8:
        break;
    }
    return f(self.bvh8_);
  }

 public:
  explicit BvhIntersector(const BackendOptions& options) : options_(options) {
    info_.name = "bvh/" + std::string(to_string(options.build.builder)) + "/" +
                 std::string(to_string(options.triangle_test));
    if (options.layout != BvhLayout::kBvh8)
      info_.name.append("/").append(to_string(options.layout));
    info_.has_tree_stats = true;
  }

  // An animated scene (Scene::animation) will be updated: its build's freed
  // arrays are kept for the first rebuild already, as update() keeps them
  // (the embree backend makes such a scene RTC_SCENE_FLAG_DYNAMIC).
  void build(const Scene& scene) override {
    if (scene.animation.animated() && !retain_buffers_) retain_buffers_.emplace();
    info_.build_ms = rebuild(scene, StatsPass::kAfter);
  }

  // The caller moved vertices (same meshes, triangle indices and counts).
  // Whatever the strategy, a change of the set of valid triangles (one became
  // degenerate or non-finite, or valid again) or of the mesh layout forces a
  // rebuild: the tree only holds the triangles that were valid at its build.
  // After a refit, info().stats has the refitted sah_cost; the other
  // figures are those of the last rebuild and still true. A rebuild here
  // reports sah_cost, nodes and the triangle counts, and the other figures
  // (tree_hash and the leaf and depth figures; zero without them) only with
  // BackendOptions::full_stats_on_update, computed beside the flattening.
  // A refit allocates nothing: it rewrites the existing nodes and triangles.
  // build_ms: the whole update (checks, refit, rebuild). From the first
  // update on, the backend keeps the freed build arrays for the next rebuild
  // (huge_buffer.h).
  void update(const Scene& scene) override {
    const auto start = std::chrono::steady_clock::now();
    if (!retain_buffers_) retain_buffers_.emplace();
    bool rebuilt = true;
    double ms = 0.0;
    if (options_.update == UpdateStrategy::kRebuild || !same_layout(scene) ||
        invalid_became_valid(scene)) {
      ms = ms_since(start) + rebuild(scene, update_stats());
    } else {
      // Only the array this backend's triangle test reads is re-gathered.
      const RefitTriangles write = test_arrays();
      const RefitResult r =
          with_layout(*this, [&](auto& bvh) { return refit(bvh, scene, write, &refit_index_); });
      if (!r.valid || (options_.update == UpdateStrategy::kAdaptive &&
                       r.sah_cost > double(options_.adaptive_factor) * rebuild_sah_cost_)) {
        ms = ms_since(start) + rebuild(scene, update_stats());
      } else {
        info_.stats.sah_cost = r.sah_cost;
        rebuilt = false;
        ms = ms_since(start);
      }
    }
    info_.rebuilt = rebuilt;
    info_.build_ms = ms;
  }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    if (hits.size() < rays.size())
      throw std::invalid_argument("intersect: fewer hit slots than rays");
    with_layout(*this, [&](const auto& bvh) {
      if (options_.triangle_test == TriangleTestKind::kMoller)
        trace_batch<MollerTest, false>(bvh, rays, hits.data(), nullptr);
      else
        trace_batch<WatertightTest, false>(bvh, rays, hits.data(), nullptr);
    });
  }

  void occluded(std::span<const Ray> rays, std::span<uint8_t> result) const override {
    if (result.size() < rays.size())
      throw std::invalid_argument("occluded: fewer result slots than rays");
    with_layout(*this, [&](const auto& bvh) {
      if (options_.triangle_test == TriangleTestKind::kMoller)
        trace_batch<MollerTest, true>(bvh, rays, nullptr, result.data());
      else
        trace_batch<WatertightTest, true>(bvh, rays, nullptr, result.data());
    });
  }

  BuildInfo info() const override { return info_; }

 private:
  // When a rebuild computes the full tree statistics (compute_tree_stats):
  // after the timed part, as a task beside the flattening (counted where it
  // outlasts it; on 1 thread in full), or not (TreeStats' counts and
  // sah_cost only, which the build has anyway).
  enum class StatsPass { kAfter, kBeside, kNone };
  StatsPass update_stats() const {
    return options_.full_stats_on_update ? StatsPass::kBeside : StatsPass::kNone;
  }

  // Full build; returns its ms: prim info + build + flatten + what update()
  // needs later (layout record, refit index, the new tree's SAH cost).
  double rebuild(const Scene& scene, StatsPass stats_pass) {
    const auto start = std::chrono::steady_clock::now();
    const PrimInfo prims = make_prim_info(scene);
    const BuildTree tree = build_tree(prims, options_.build);
    // The last build's triangle arrays (and refit index) are rewritten in
    // place: over the same triangles they have the sizes already, so a
    // rebuild of a deforming mesh faults in no fresh pages for them.
    LeafTriangles triangles =
        with_layout(*this, [](auto& bvh) { return std::move(bvh.triangles); });
    // Only the layout in use is kept; the others are left empty. Until the
    // new one is made, no layout is recorded: should making it throw, the
    // next update() finds the layout changed and rebuilds, instead of
    // refitting an empty tree.
    layout_.clear();
    bvh2_ = Bvh2{};
    bvh4_ = WideBvh<4>{};
    bvh8_ = WideBvh<8>{};
    const auto make_layout = [&] {
      with_layout(*this, [&](auto& bvh) {
        // The node pass beside the triangle pass and the refit index.
        tbb::parallel_invoke([&] { flatten_nodes_into(bvh, tree, prims); },
                             [&] {
                               gather_leaf_triangles(tree, prims, scene, test_arrays(), triangles);
                               make_refit_index(triangles, scene, refit_index_);
                             });
        bvh.triangles = std::move(triangles);
        rebuild_sah_cost_ = sah_cost_of(bvh);  // = stats.sah_cost up to rounding
        info_.memory_bytes = bvh.memory_bytes();
      });
      record_layout(scene, prims);
    };
    TreeStats stats;
    double ms = 0.0;
    switch (stats_pass) {
      case StatsPass::kBeside:
        tbb::parallel_invoke(make_layout, [&] { stats = compute_tree_stats(tree, prims); });
        ms = ms_since(start);
        break;
      case StatsPass::kAfter:
        make_layout();
        ms = ms_since(start);
        stats = compute_tree_stats(tree, prims);
        break;
      case StatsPass::kNone:
        make_layout();
        ms = ms_since(start);
        stats.triangles = prims.size();
        stats.invalid_triangles = prims.invalid;
        stats.nodes = tree.nodes.size();
        stats.sah_cost = rebuild_sah_cost_;
        break;
    }
    info_.stats = stats;
    info_.rebuilt = true;
    return ms;
  }

  // Only the triangle array the test reads is kept (and refitted).
  TriangleArrays test_arrays() const {
    return options_.triangle_test == TriangleTestKind::kMoller ? TriangleArrays::kEdges
                                                               : TriangleArrays::kVerts;
  }
  static void flatten_nodes_into(Bvh2& out, const BuildTree& tree, const PrimInfo& prims) {
    out = flatten_nodes(tree, prims);
  }
  template <int N>
  static void flatten_nodes_into(WideBvh<N>& out, const BuildTree& tree, const PrimInfo& prims) {
    out = flatten_wide_nodes<N>(tree, prims);
  }
  static double sah_cost_of(const Bvh2& bvh) { return bvh2_sah_cost(bvh); }
  template <int N>
  static double sah_cost_of(const WideBvh<N>& bvh) {
    return wide_sah_cost(bvh);
  }

  // What the tree was built over: per mesh its vertex and triangle counts,
  // and the triangles left out as invalid (usually none).
  void record_layout(const Scene& scene, const PrimInfo& prims) {
    layout_.resize(scene.meshes.size());
    for (size_t g = 0; g < scene.meshes.size(); ++g)
      layout_[g] = {scene.meshes[g].vertex_count(), scene.meshes[g].triangle_count()};
    invalid_.clear();
    if (prims.invalid == 0) return;
    invalid_.reserve(prims.invalid);
    for (size_t g = 0; g < scene.meshes.size(); ++g)
      for (size_t i = 0; i < scene.meshes[g].triangle_count(); ++i)
        if (!scene.meshes[g].triangle_valid(i))
          invalid_.push_back({static_cast<uint32_t>(g), static_cast<uint32_t>(i)});
  }

  bool same_layout(const Scene& scene) const {
    if (scene.meshes.size() != layout_.size()) return false;
    for (size_t g = 0; g < layout_.size(); ++g)
      if (layout_[g].vertices != scene.meshes[g].vertex_count() ||
          layout_[g].triangles != scene.meshes[g].triangle_count())
        return false;
    return true;
  }

  bool invalid_became_valid(const Scene& scene) const {
    for (const PrimRef& r : invalid_)
      if (scene.meshes[r.geom_id].triangle_valid(r.prim_id)) return true;
    return false;
  }

  struct MeshLayout {
    size_t vertices = 0;
    size_t triangles = 0;
  };

  BackendOptions options_;
  Bvh2 bvh2_;
  WideBvh<4> bvh4_;
  WideBvh<8> bvh8_;
  BuildInfo info_;
  std::vector<MeshLayout> layout_;                     // per mesh at the last rebuild
  std::vector<PrimRef> invalid_;                       // triangles left out at the last rebuild
  RefitIndex refit_index_;                             // leaf-order vertex indices for refit()
  double rebuild_sah_cost_ = 0.0;                      // sah_cost right after the last rebuild
  std::optional<HugeBufferRetention> retain_buffers_;  // held once animated
};

}  // namespace

std::unique_ptr<Intersector> make_bvh_intersector(const BackendOptions& options) {
  return std::make_unique<BvhIntersector>(options);
}

}  // namespace hprt
