// hprt's own BVH behind the Intersector interface: prim info -> build tree
// (the builder named in the options, oneTBB inside the caller's task arena)
// -> tree statistics -> the traversal layout named in the options (binary, or
// wide 4/8 collapsed from the same tree); batches of rays traced in parallel
// blocks with one switch per batch into a fully inlined traversal.
// update(): per BackendOptions::update, a full rebuild, a refit over the last
// build's topology (bvh/refit.h), or adaptive (refit, then rebuild when the
// refitted SAH cost exceeds adaptive_factor x the cost at the last rebuild).
#include "backends/bvh_backend.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include "bvh/builders.h"
#include "bvh/flatten.h"
#include "bvh/flatten_wide.h"
#include "bvh/refit.h"
#include "bvh/refit_wide.h"
#include "bvh/traverse.h"
#include "bvh/traverse_wide.h"

namespace hprt {
namespace {

constexpr size_t kGrain = 128;  // rays per parallel task

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

template <typename Test, bool kAnyHit>
bool trace_one(const FlatBvh& bvh, const Ray& ray, Hit& hit) {
  return traverse<Test, kAnyHit>(bvh, ray, hit);
}
template <typename Test, bool kAnyHit, int N>
bool trace_one(const WideBvh<N>& bvh, const Ray& ray, Hit& hit) {
  return traverse_wide<Test, kAnyHit>(bvh, ray, hit);
}

template <typename Test, typename Bvh>
void intersect_batch(const Bvh& bvh, std::span<const Ray> rays, std::span<Hit> hits) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), kGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        Hit h;
                        if (ray_is_valid(rays[i])) trace_one<Test, false>(bvh, rays[i], h);
                        hits[i] = h;
                      }
                    });
}

template <typename Test, typename Bvh>
void occluded_batch(const Bvh& bvh, std::span<const Ray> rays, std::span<uint8_t> out) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), kGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        Hit h;
                        out[i] = ray_is_valid(rays[i]) && trace_one<Test, true>(bvh, rays[i], h);
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

  void build(const Scene& scene) override { info_.build_ms = rebuild(scene); }

  // The caller moved vertices (same meshes, triangle indices and counts).
  // Whatever the strategy, a change of the set of valid triangles (one became
  // degenerate or non-finite, or valid again) or of the mesh layout forces a
  // rebuild: the tree only holds the triangles that were valid at its build.
  // After a refit, info().stats has the refitted sah_cost; the topology
  // figures (nodes, leaves, depth, leaf sizes, triangle counts) are those of
  // the last rebuild and still true, and tree_hash is the last rebuild's.
  // A refit allocates nothing: it rewrites the existing nodes and triangles.
  // build_ms: the whole update (checks, refit, rebuild), without the
  // reporting-only tree statistics of a rebuild (as for build()).
  void update(const Scene& scene) override {
    const auto start = std::chrono::steady_clock::now();
    bool rebuilt = true;
    double ms = 0.0;
    if (options_.update == UpdateStrategy::kRebuild || !same_layout(scene) ||
        invalid_became_valid(scene)) {
      ms = ms_since(start) + rebuild(scene);
    } else {
      // Only the array this backend's triangle test reads is re-gathered.
      const RefitTriangles write = options_.triangle_test == TriangleTestKind::kMoller
                                       ? RefitTriangles::kEdges
                                       : RefitTriangles::kVerts;
      const RefitResult r =
          with_layout(*this, [&](auto& bvh) { return refit(bvh, scene, write, &refit_index_); });
      if (!r.valid || (options_.update == UpdateStrategy::kAdaptive &&
                       r.sah_cost > double(options_.adaptive_factor) * rebuild_sah_cost_)) {
        ms = ms_since(start) + rebuild(scene);
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
        intersect_batch<MollerTest>(bvh, rays, hits);
      else
        intersect_batch<WatertightTest>(bvh, rays, hits);
    });
  }

  void occluded(std::span<const Ray> rays, std::span<uint8_t> result) const override {
    if (result.size() < rays.size())
      throw std::invalid_argument("occluded: fewer result slots than rays");
    with_layout(*this, [&](const auto& bvh) {
      if (options_.triangle_test == TriangleTestKind::kMoller)
        occluded_batch<MollerTest>(bvh, rays, result);
      else
        occluded_batch<WatertightTest>(bvh, rays, result);
    });
  }

  BuildInfo info() const override { return info_; }

 private:
  // Full build; returns its ms: prim info + build + flatten + what update()
  // needs later (layout record, the new tree's SAH cost, parallel). The tree
  // statistics and hash (sequential, for reporting) are computed after that.
  double rebuild(const Scene& scene) {
    const auto start = std::chrono::steady_clock::now();
    const PrimInfo prims = make_prim_info(scene);
    const BuildTree tree = build_tree(prims, options_.build);
    // Only the layout in use is kept; the others are left empty.
    bvh2_ = FlatBvh{};
    bvh4_ = WideBvh<4>{};
    bvh8_ = WideBvh<8>{};
    record_layout(scene, prims);
    with_layout(*this, [&](auto& bvh) {
      flatten_into(bvh, tree, prims, scene);
      refit_index_ = make_refit_index(bvh.triangles, scene);
      rebuild_sah_cost_ = sah_cost_of(bvh);  // = stats.sah_cost up to rounding
      info_.memory_bytes = bvh.memory_bytes();
    });
    const double ms = ms_since(start);
    info_.stats = compute_tree_stats(tree, prims);
    info_.rebuilt = true;
    return ms;
  }

  static void flatten_into(FlatBvh& out, const BuildTree& tree, const PrimInfo& prims,
                           const Scene& scene) {
    out = flatten(tree, prims, scene);
  }
  template <int N>
  static void flatten_into(WideBvh<N>& out, const BuildTree& tree, const PrimInfo& prims,
                           const Scene& scene) {
    out = flatten_wide<N>(tree, prims, scene);
  }
  static double sah_cost_of(const FlatBvh& bvh) { return flat_sah_cost(bvh); }
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
  FlatBvh bvh2_;
  WideBvh<4> bvh4_;
  WideBvh<8> bvh8_;
  BuildInfo info_;
  std::vector<MeshLayout> layout_;  // per mesh at the last rebuild
  std::vector<PrimRef> invalid_;    // triangles left out at the last rebuild
  RefitIndex refit_index_;          // leaf-order vertex indices for refit()
  double rebuild_sah_cost_ = 0.0;   // sah_cost right after the last rebuild
};

}  // namespace

std::unique_ptr<Intersector> make_bvh_intersector(const BackendOptions& options) {
  return std::make_unique<BvhIntersector>(options);
}

}  // namespace hprt
