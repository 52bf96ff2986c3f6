// hprt's own BVH behind the Intersector interface: prim info -> build tree
// (the builder named in the options, oneTBB inside the caller's task arena)
// -> tree statistics -> flattened binary layout; batches of rays traced in
// parallel blocks with one switch per batch into a fully inlined traversal.
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
#include "bvh/refit.h"
#include "bvh/traverse.h"

namespace hprt {
namespace {

constexpr size_t kGrain = 128;  // rays per parallel task

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

template <typename Test>
void intersect_batch(const FlatBvh& bvh, std::span<const Ray> rays, std::span<Hit> hits) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), kGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        Hit h;
                        if (ray_is_valid(rays[i])) traverse<Test, false>(bvh, rays[i], h);
                        hits[i] = h;
                      }
                    });
}

template <typename Test>
void occluded_batch(const FlatBvh& bvh, std::span<const Ray> rays, std::span<uint8_t> out) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), kGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        Hit h;
                        out[i] = ray_is_valid(rays[i]) && traverse<Test, true>(bvh, rays[i], h);
                      }
                    });
}

class BvhIntersector final : public Intersector {
 public:
  explicit BvhIntersector(const BackendOptions& options) : options_(options) {
    info_.name = "bvh/" + std::string(to_string(options.build.builder)) + "/" +
                 std::string(to_string(options.triangle_test));
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
      const RefitResult r =
          refit(bvh_, scene,
                options_.triangle_test == TriangleTestKind::kMoller ? RefitTriangles::kEdges
                                                                    : RefitTriangles::kVerts,
                &refit_index_);
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
    switch (options_.triangle_test) {
      case TriangleTestKind::kWatertight:
        intersect_batch<WatertightTest>(bvh_, rays, hits);
        break;
      case TriangleTestKind::kMoller:
        intersect_batch<MollerTest>(bvh_, rays, hits);
        break;
    }
  }

  void occluded(std::span<const Ray> rays, std::span<uint8_t> result) const override {
    if (result.size() < rays.size())
      throw std::invalid_argument("occluded: fewer result slots than rays");
    switch (options_.triangle_test) {
      case TriangleTestKind::kWatertight:
        occluded_batch<WatertightTest>(bvh_, rays, result);
        break;
      case TriangleTestKind::kMoller:
        occluded_batch<MollerTest>(bvh_, rays, result);
        break;
    }
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
    bvh_ = flatten(tree, prims, scene);
    record_layout(scene, prims);
    refit_index_ = make_refit_index(bvh_, scene);
    rebuild_sah_cost_ = flat_sah_cost(bvh_);  // = stats.sah_cost up to rounding
    const double ms = ms_since(start);
    info_.stats = compute_tree_stats(tree, prims);
    info_.memory_bytes = bvh_.memory_bytes();
    info_.rebuilt = true;
    return ms;
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
  FlatBvh bvh_;
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
