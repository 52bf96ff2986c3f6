// hprt's own BVH behind the Intersector interface: glue between the scene,
// the builders (bvh/builders), the traversal layout named in the options
// (bvh/layout, made from the build tree with the triangle pass beside the
// node pass), the batch entry points (bvh/traverse/trace_batch.h) and the
// refits (bvh/refit). When update() refits and when it rebuilds is
// update_policy.h's; what the tree was built over, mesh_record.h's.
#include "backends/bvh_backend.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends/auto_update_policy.h"
#include "backends/busy_clock.h"
#include "backends/mesh_record.h"
#include "backends/update_policy.h"
#include "bvh/builders/builders.h"
#include "bvh/layout/flatten_bvh2.h"
#include "bvh/layout/flatten_wide.h"
#include "bvh/memory/huge_buffer.h"
#include "bvh/refit/refit_bvh2.h"
#include "bvh/refit/refit_wide.h"
#include "bvh/traverse/trace_batch.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "core/triangle_normal.h"

namespace hprt {
namespace {

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
  explicit BvhIntersector(const BackendOptions& options)
      : options_(options),
        auto_policy_(options.build.builder != BuilderKind::kMorton, options.adaptive_factor) {
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
    drop_leaf_normals();
    if (scene.animation.animated() && !retain_buffers_) retain_buffers_.emplace();
    info_.build_ms = rebuild(scene, StatsPass::kAfter, options_.build);
    auto_policy_.rebuilt(configured_choice(), info_.build_ms, rebuild_sah_cost_);
    time_queries_ = options_.update == UpdateStrategy::kAuto && retain_buffers_;
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
  // A refit allocates nothing (the refit index aside, on the first refit
  // after a build of a scene not known to be animated): it rewrites the
  // existing nodes and triangles.
  // build_ms: the whole update (checks, refit, rebuild). From the first
  // update on, the backend keeps the freed build arrays for the next rebuild
  // (huge_buffer.h).
  void update(const Scene& scene) override {
    const auto start = Clock::now();
    drop_leaf_normals();
    if (!retain_buffers_) retain_buffers_.emplace();
    const bool automatic = options_.update == UpdateStrategy::kAuto;
    const double query_ms = busy_.take_ms();  // since the last update (auto only)
    time_queries_ = automatic;
    AutoUpdatePolicy::Choice choice = AutoUpdatePolicy::Choice::kRefit;
    const AutoUpdatePolicy::Queries queries{query_ms, info_.stats.sah_cost};
    const bool forced = must_rebuild(options_.update, built_over_.fits(scene));
    if (forced)
      choice = automatic ? auto_policy_.forced_rebuild() : configured_choice();
    else if (automatic)  // a refit that would be thrown away is not made
      choice = auto_policy_.predicted_rebuild(queries);
    if (!forced && choice == AutoUpdatePolicy::Choice::kRefit) {
      // Only the array this backend's triangle test reads is re-gathered.
      const RefitTriangles write = test_arrays();
      const RefitResult r = with_layout(*this, [&](auto& bvh) {
        if (!refit_index_ready_) make_refit_index(bvh.triangles, scene, refit_index_);
        refit_index_ready_ = true;
        return refit(bvh, scene, write, &refit_index_);
      });
      if (!r.valid)
        choice = automatic ? auto_policy_.forced_rebuild() : configured_choice();
      else if (automatic)
        choice = auto_policy_.after_refit(r.sah_cost, queries);
      else if (rebuild_after_refit(options_, r.valid, r.sah_cost, rebuild_sah_cost_))
        choice = configured_choice();
      if (choice == AutoUpdatePolicy::Choice::kRefit) info_.stats.sah_cost = r.sah_cost;
    }
    double ms = ms_since(start);
    if (choice != AutoUpdatePolicy::Choice::kRefit) {
      BuildOptions build = options_.build;
      if (choice == AutoUpdatePolicy::Choice::kMorton) build.builder = BuilderKind::kMorton;
      const double rebuild_ms = rebuild(scene, update_stats(), build);
      ms += rebuild_ms;
      if (automatic) auto_policy_.rebuilt(choice, rebuild_ms, rebuild_sah_cost_);
    }
    info_.rebuilt = choice != AutoUpdatePolicy::Choice::kRefit;
    if (!info_.rebuilt) info_.rebuilt_with.clear();
    info_.build_ms = ms;
  }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    if (hits.size() < rays.size())
      throw std::invalid_argument("intersect: fewer hit slots than rays");
    const BusyClock::Scope timed(query_clock());
    with_layout(*this, [&](const auto& bvh) {
      intersect_batch(bvh, options_.triangle_test, rays, hits.data());
    });
  }

  void intersect_columns(const Scene& scene, const RayInput& rays,
                         const HitColumns& out) const override {
    const BusyClock::Scope timed(query_clock());
    with_layout(*this, [&](const auto& bvh) {
      const LeafTriangles& tris = bvh.triangles;
      const bool table = out.normal && !tris.holds(TriangleArrays::kVerts);
      const HitColumnWriter writer{out, &tris, table ? leaf_normals(scene, tris) : nullptr};
      intersect_batch(bvh, options_.triangle_test, rays, nullptr, &writer);
    });
  }

  void occluded(const RayInput& rays, std::span<uint8_t> result) const override {
    if (result.size() < rays.size())
      throw std::invalid_argument("occluded: fewer result slots than rays");
    const BusyClock::Scope timed(query_clock());
    with_layout(*this, [&](const auto& bvh) {
      occluded_batch(bvh, options_.triangle_test, rays, result.data());
    });
  }
  void count(const RayInput& rays, std::span<uint32_t> counts) const override {
    if (counts.size() < rays.size())
      throw std::invalid_argument("count: fewer result slots than rays");
    const BusyClock::Scope timed(query_clock());
    with_layout(*this, [&](const auto& bvh) {
      count_batch(bvh, options_.triangle_test, rays, counts.data());
    });
  }

  void intersect_all(const RayInput& rays, uint32_t max_per_ray, HitLists& out) const override {
    const BusyClock::Scope timed(query_clock());
    with_layout(*this, [&](const auto& bvh) {
      all_batch(bvh, options_.triangle_test, rays, max_per_ray, out);
    });
  }

  // The point queries read the exact vertices, which only the watertight
  // test's arrays hold.
  void locate(std::span<const Vec3f> points, std::span<PointLocation> out) const override {
    if (out.size() < points.size())
      throw std::invalid_argument("locate: fewer result slots than points");
    require_vertices("inside");
    const BusyClock::Scope timed(query_clock());
    with_layout(*this, [&](const auto& bvh) { locate_batch(bvh, points, out.data()); });
  }

  void closest(std::span<const Vec3f> points, float max_distance,
               std::span<ClosestPoint> out) const override {
    if (out.size() < points.size())
      throw std::invalid_argument("closest: fewer result slots than points");
    require_vertices("closest");
    const BusyClock::Scope timed(query_clock());
    with_layout(*this,
                [&](const auto& bvh) { closest_batch(bvh, points, max_distance, out.data()); });
  }

  // memory_bytes counts the leaf-order normals while they are held.
  BuildInfo info() const override {
    BuildInfo i = info_;
    if (leaf_normals_ready_.load(std::memory_order_acquire))
      i.memory_bytes += leaf_normals_.size() * sizeof(float);
    return i;
  }

 private:
  // The unit normal of each triangle in leaf order (HitColumnWriter), for a
  // tree without the exact vertices: made by its first intersect_columns
  // with normals after a build or update (12 bytes a triangle, held only
  // when asked for).
  const float* leaf_normals(const Scene& scene, const LeafTriangles& tris) const {
    if (leaf_normals_ready_.load(std::memory_order_acquire)) return leaf_normals_.data();
    const std::lock_guard lock(leaf_normals_mutex_);
    if (!leaf_normals_ready_.load(std::memory_order_relaxed)) {
      leaf_normals_.resize(3 * tris.size());
      // Isolated: while this thread waits for the loop under the lock, it
      // must not take up another task of the caller's that would lock again.
      tbb::this_task_arena::isolate([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tris.size(), 16384),
                          [&](const tbb::blocked_range<size_t>& r) {
                            for (size_t i = r.begin(); i != r.end(); ++i) {
                              const PrimRef& ref = tris.refs[i];
                              triangle_normal(scene.meshes[ref.geom_id], ref.prim_id,
                                              leaf_normals_.data() + 3 * i);
                            }
                          });
      });
      leaf_normals_ready_.store(true, std::memory_order_release);
    }
    return leaf_normals_.data();
  }
  void drop_leaf_normals() {
    leaf_normals_ready_.store(false, std::memory_order_relaxed);
    leaf_normals_ = {};
  }

  // When a rebuild computes the full tree statistics (compute_tree_stats):
  // after the timed part, as a task beside the flattening (counted where it
  // outlasts it; on 1 thread in full), or not (TreeStats' counts and
  // sah_cost only, which the build has anyway).
  enum class StatsPass { kAfter, kBeside, kNone };
  StatsPass update_stats() const {
    return options_.full_stats_on_update ? StatsPass::kBeside : StatsPass::kNone;
  }

  // Full build; returns its ms: prim info + build + flatten + what update()
  // needs later (layout record, the new tree's SAH cost, and the refit index
  // when animated).
  double rebuild(const Scene& scene, StatsPass stats_pass, const BuildOptions& build) {
    const auto start = Clock::now();
    PrimInfo prims = make_prim_info(scene, builder_reads_centroids(build.builder));
    // The primitive boxes (24 bytes a triangle) go as soon as the builder is
    // done with them, kept only for a Morton tree (builders.h): the layout
    // takes the few it needs from the scene.
    const BuildTree tree = build_tree_releasing_bounds(prims, build);
    // The last build's triangle arrays (and refit index) are rewritten in
    // place: over the same triangles they have the sizes already, so a
    // rebuild of a deforming mesh faults in no fresh pages for them.
    LeafTriangles triangles =
        with_layout(*this, [](auto& bvh) { return std::move(bvh.triangles); });
    // Only the layout in use is kept; the others are left empty. Until the
    // new one is made, no layout is recorded: should making it throw, the
    // next update() finds the layout changed and rebuilds, instead of
    // refitting an empty tree.
    built_over_.clear();
    refit_index_ready_ = false;
    bvh2_ = Bvh2{};
    bvh4_ = WideBvh<4>{};
    bvh8_ = WideBvh<8>{};
    const auto make_layout = [&] {
      with_layout(*this, [&](auto& bvh) {
        // The node pass beside the triangle pass (and the refit index and
        // the SAH cost, the layout's up to rounding: a wide node's collapsed
        // binary nodes and split leaves count as in the build tree).
        tbb::parallel_invoke([&] { flatten_nodes_into(bvh, tree, prims, scene); },
                             [&] {
                               gather_leaf_triangles(tree, prims, scene, test_arrays(), triangles);
                               if (retain_buffers_)
                                 make_refit_index(triangles, scene, refit_index_);
                               rebuild_sah_cost_ = build_tree_sah_cost(tree);
                             });
        refit_index_ready_ = bool(retain_buffers_);
        bvh.triangles = std::move(triangles);
        info_.memory_bytes = bvh.memory_bytes();
      });
      built_over_.record(scene, prims);
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
    info_.rebuilt_with = to_string(build.builder);
    return ms;
  }

  // The rebuild the configured builder makes, in the auto policy's terms.
  AutoUpdatePolicy::Choice configured_choice() const {
    return options_.build.builder == BuilderKind::kMorton ? AutoUpdatePolicy::Choice::kMorton
                                                          : AutoUpdatePolicy::Choice::kSah;
  }
  // Queries are timed for the auto policy once the backend is animated.
  BusyClock* query_clock() const { return time_queries_ ? &busy_ : nullptr; }

  void require_vertices(const char* query) const {
    if (options_.triangle_test == TriangleTestKind::kMoller)
      throw OptionError("isect", std::string("the mt triangle test keeps no exact vertices, so it "
                                             "does not answer ") +
                                     query + " queries (the watertight test, the default, does)");
  }

  // Only the triangle array the test reads is kept (and refitted).
  TriangleArrays test_arrays() const {
    return options_.triangle_test == TriangleTestKind::kMoller ? TriangleArrays::kEdges
                                                               : TriangleArrays::kVerts;
  }
  static void flatten_nodes_into(Bvh2& out, const BuildTree& tree, const PrimInfo& prims,
                                 const Scene&) {
    out = flatten_nodes(tree, prims);
  }
  template <int N>
  static void flatten_nodes_into(WideBvh<N>& out, const BuildTree& tree, const PrimInfo& prims,
                                 const Scene& scene) {
    out = flatten_wide_nodes<N>(tree, prims, scene);
  }

  BackendOptions options_;
  Bvh2 bvh2_;
  WideBvh<4> bvh4_;
  WideBvh<8> bvh8_;
  BuildInfo info_;
  MeshRecord built_over_;  // the meshes at the last rebuild
  // Leaf-order vertex indices for refit(): made with the tree when the
  // backend is animated (retain_buffers_), else by the first refit, so that a
  // one-off build does not pay for it.
  RefitIndex refit_index_;
  bool refit_index_ready_ = false;
  double rebuild_sah_cost_ = 0.0;                      // sah_cost right after the last rebuild
  std::optional<HugeBufferRetention> retain_buffers_;  // held once animated
  AutoUpdatePolicy auto_policy_;
  bool time_queries_ = false;
  mutable std::vector<float> leaf_normals_;  // leaf_normals()
  mutable std::mutex leaf_normals_mutex_;
  mutable std::atomic<bool> leaf_normals_ready_{false};
  mutable BusyClock busy_;  // query time since the last update, when time_queries_
};

}  // namespace

std::unique_ptr<Intersector> make_bvh_intersector(const BackendOptions& options) {
  return std::make_unique<BvhIntersector>(options);
}

}  // namespace hprt
