// Tree quality against Embree's own generic binned-SAH builder (rtcBuildBVH):
// a binary tree with leaves of 1-4 primitives and the same SAH constants as
// ours, its normalised SAH cost computed exactly as tree_stats.cpp does for
// our trees (inner nodes 1, leaves their primitive count, weighted by
// SA(node)/SA(root)). Reports both costs, their ratio and both build times.
// Scene: a generated 1M-triangle sphere, or HPRT_MESH=path.
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <chrono>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <vector>

#include "bvh/builders.h"
#include "core/parallel.h"
#include "io/generate_mesh.h"
#include "io/scene_reader.h"

namespace {

struct EmbreeNode {
  bool leaf = false;
  unsigned count = 0;  // leaf: primitives
  EmbreeNode* child[2] = {nullptr, nullptr};
  hprt::AABB child_bounds[2];
  hprt::AABB leaf_bounds;
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int, void*) {
  return new (rtcThreadLocalAlloc(alloc, sizeof(EmbreeNode), 16)) EmbreeNode;
}
void set_children(void* node, void** children, unsigned int n, void*) {
  for (unsigned i = 0; i < n && i < 2; ++i)
    static_cast<EmbreeNode*>(node)->child[i] = static_cast<EmbreeNode*>(children[i]);
}
void set_bounds(void* node, const RTCBounds** b, unsigned int n, void*) {
  for (unsigned i = 0; i < n && i < 2; ++i)
    static_cast<EmbreeNode*>(node)->child_bounds[i] =
        hprt::AABB({b[i]->lower_x, b[i]->lower_y, b[i]->lower_z},
                   {b[i]->upper_x, b[i]->upper_y, b[i]->upper_z});
}
void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t n, void*) {
  auto* leaf = new (rtcThreadLocalAlloc(alloc, sizeof(EmbreeNode), 16)) EmbreeNode;
  leaf->leaf = true;
  leaf->count = unsigned(n);
  for (size_t i = 0; i < n; ++i)
    leaf->leaf_bounds.extend(hprt::AABB({prims[i].lower_x, prims[i].lower_y, prims[i].lower_z},
                                        {prims[i].upper_x, prims[i].upper_y, prims[i].upper_z}));
  return leaf;
}

// Σ SA(node)·weight over the tree under `node` whose box is `box`.
double sah_sum(const EmbreeNode* node, const hprt::AABB& box) {
  if (node->leaf) return double(box.half_area()) * node->count;
  double s = box.half_area();
  for (int i = 0; i < 2; ++i)
    if (node->child[i]) s += sah_sum(node->child[i], node->child_bounds[i]);
  return s;
}

const hprt::Scene& bench_scene() {
  static std::unique_ptr<hprt::Scene> scene;
  if (!scene) {
    if (const char* path = std::getenv("HPRT_MESH")) {
      scene = std::make_unique<hprt::Scene>(hprt::load_scene(path));
    } else {
      scene = std::make_unique<hprt::Scene>();
      hprt::GenerateSpec spec;
      spec.kind = "sphere";
      spec.tris = 1000000;
      scene->add_mesh(hprt::generate_mesh(spec));
    }
  }
  return *scene;
}

// arg: threads (0 = all)
void BM_SahVsEmbreeBuildBVH(benchmark::State& state) {
  const int threads = int(state.range(0));
  const hprt::Scene& scene = bench_scene();
  const hprt::PrimInfo prims = hprt::make_prim_info(scene);
  std::vector<RTCBuildPrimitive> base(prims.size()), work(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) {
    const hprt::AABB& b = prims.bounds[i];
    base[i] = RTCBuildPrimitive{b.min.x, b.min.y, b.min.z, prims.refs[i].geom_id,
                                b.max.x, b.max.y, b.max.z, uint32_t(i)};
  }
  const std::string config = "threads=" + std::to_string(hprt::resolve_threads(threads));
  RTCDevice device = rtcNewDevice(config.c_str());
  RTCBVH bvh = rtcNewBVH(device);
  double embree_ms = 0.0, ours_ms = 0.0, embree_sah = 0.0, ours_sah = 0.0;
  hprt::BuildOptions options;  // parallel, 32 bins, leaves <= 4, C_trav = C_isect = 1
  hprt::run_with_threads(threads, [&] {
    for (auto _ : state) {
      work = base;  // rtcBuildBVH reorders the primitive array
      RTCBuildArguments args = rtcDefaultBuildArguments();
      args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
      args.maxBranchingFactor = 2;
      args.maxDepth = 1024;
      args.minLeafSize = 1;
      args.maxLeafSize = uint32_t(options.max_leaf_size);
      args.traversalCost = options.sah.traversal_cost;
      args.intersectionCost = options.sah.intersection_cost;
      args.bvh = bvh;
      args.primitives = work.data();
      args.primitiveCount = work.size();
      args.primitiveArrayCapacity = work.size();
      args.createNode = create_node;
      args.setNodeChildren = set_children;
      args.setNodeBounds = set_bounds;
      args.createLeaf = create_leaf;
      auto t0 = std::chrono::steady_clock::now();
      auto* root = static_cast<EmbreeNode*>(rtcBuildBVH(&args));
      auto t1 = std::chrono::steady_clock::now();
      if (!root) throw std::runtime_error("rtcBuildBVH failed");
      embree_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
      embree_sah = sah_sum(root, prims.scene_bounds) / prims.scene_bounds.half_area();

      t0 = std::chrono::steady_clock::now();
      const hprt::BuildTree tree = hprt::build_tree(prims, options);
      t1 = std::chrono::steady_clock::now();
      ours_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
      ours_sah = hprt::compute_tree_stats(tree, prims).sah_cost;
      state.SetIterationTime((embree_ms + ours_ms) / 1e3);
    }
  });
  rtcReleaseBVH(bvh);
  rtcReleaseDevice(device);
  state.counters["embree_ms"] = embree_ms;
  state.counters["ours_ms"] = ours_ms;
  state.counters["embree_sah"] = embree_sah;
  state.counters["ours_sah"] = ours_sah;
  state.counters["sah_ratio"] = ours_sah / embree_sah;
  state.counters["threads"] = hprt::resolve_threads(threads);
  state.counters["triangles"] = double(prims.size());
}

BENCHMARK(BM_SahVsEmbreeBuildBVH)
    ->Arg(1)
    ->Arg(0)
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

}  // namespace
