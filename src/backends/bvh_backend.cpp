// hprt's own BVH behind the Intersector interface: prim info -> build tree
// (the builder named in the options, oneTBB inside the caller's task arena)
// -> tree statistics -> flattened binary layout; batches of rays traced in
// parallel blocks with one switch per batch into a fully inlined traversal.
#include "backends/bvh_backend.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <stdexcept>
#include <string>

#include "bvh/builders.h"
#include "bvh/flatten.h"
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

  void build(const Scene& scene) override {
    const auto start = std::chrono::steady_clock::now();
    const PrimInfo prims = make_prim_info(scene);
    const BuildTree tree = build_tree(prims, options_.build);
    bvh_ = flatten(tree, prims, scene);
    info_.build_ms = ms_since(start);  // prim info + build + flatten
    info_.stats = compute_tree_stats(tree, prims);
    info_.memory_bytes = bvh_.memory_bytes();
    info_.rebuilt = true;
  }

  // Vertices moved: for now always a full rebuild (correct for any change).
  // A refit would keep the BuildTree/PrimInfo of the last build and update
  // bounds bottom-up here, choosing per options_.update.
  void update(const Scene& scene) override { build(scene); }

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
  BackendOptions options_;
  FlatBvh bvh_;
  BuildInfo info_;
};

}  // namespace

std::unique_ptr<Intersector> make_bvh_intersector(const BackendOptions& options) {
  return std::make_unique<BvhIntersector>(options);
}

}  // namespace hprt
