// rtcBuildBVH with callbacks that record a binary tree (child boxes on inner
// nodes, primitive counts on leaves) in Embree's thread-local allocator, then
// a recursive SAH sum over it. Nodes live until the next build or release.
#include "bench/bench_embree_bvh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "core/aabb.h"
#include "core/parallel.h"

namespace hprt::bench {
namespace {

struct EmbreeNode {
  bool leaf = false;
  unsigned count = 0;  // leaf: primitives
  EmbreeNode* child[2] = {nullptr, nullptr};
  AABB child_bounds[2];
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
        AABB({b[i]->lower_x, b[i]->lower_y, b[i]->lower_z},
             {b[i]->upper_x, b[i]->upper_y, b[i]->upper_z});
}
void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive*, size_t n, void*) {
  auto* leaf = new (rtcThreadLocalAlloc(alloc, sizeof(EmbreeNode), 16)) EmbreeNode;
  leaf->leaf = true;
  leaf->count = unsigned(n);
  return leaf;
}

struct TreeSums {
  double sah = 0.0;  // Σ SA(node)·weight
  size_t nodes = 0;
  size_t leaves = 0;
  int depth = 0;
};

void sum_tree(const EmbreeNode* node, const AABB& box, int depth, TreeSums& s) {
  ++s.nodes;
  s.depth = std::max(s.depth, depth);
  if (node->leaf) {
    ++s.leaves;
    s.sah += double(box.half_area()) * node->count;
    return;
  }
  s.sah += box.half_area();
  for (int i = 0; i < 2; ++i)
    if (node->child[i]) sum_tree(node->child[i], node->child_bounds[i], depth + 1, s);
}

}  // namespace

struct EmbreeBvhBuilder::Impl {
  RTCDevice device = nullptr;
  RTCBVH bvh = nullptr;
  std::vector<RTCBuildPrimitive> base, work;
  AABB scene_bounds;
};

EmbreeBvhBuilder::EmbreeBvhBuilder(const PrimInfo& prims, int threads)
    : impl_(std::make_unique<Impl>()) {
  impl_->scene_bounds = prims.scene_bounds;
  impl_->base.resize(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) {
    const AABB& b = prims.bounds[i];
    impl_->base[i] = RTCBuildPrimitive{b.min.x, b.min.y, b.min.z, prims.refs[i].geom_id,
                                       b.max.x, b.max.y, b.max.z, uint32_t(i)};
  }
  const std::string config = "threads=" + std::to_string(resolve_threads(threads));
  impl_->device = rtcNewDevice(config.c_str());
  if (!impl_->device) throw std::runtime_error("embree: rtcNewDevice failed");
  impl_->bvh = rtcNewBVH(impl_->device);
}

EmbreeBvhBuilder::~EmbreeBvhBuilder() {
  if (impl_->bvh) rtcReleaseBVH(impl_->bvh);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

EmbreeBvhResult EmbreeBvhBuilder::build(const BuildOptions& options) {
  EmbreeBvhResult r;
  impl_->work = impl_->base;  // rtcBuildBVH reorders the primitive array
  if (impl_->work.empty()) return r;
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = 1024;
  args.minLeafSize = 1;
  args.maxLeafSize = uint32_t(std::max(1, options.max_leaf_size));
  args.traversalCost = options.sah.traversal_cost;
  args.intersectionCost = options.sah.intersection_cost;
  args.sahBlockSize = uint32_t(options.sah.leaf_block);  // C_i per block, as ours
  args.bvh = impl_->bvh;
  args.primitives = impl_->work.data();
  args.primitiveCount = impl_->work.size();
  args.primitiveArrayCapacity = impl_->work.size();
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  const auto t0 = std::chrono::steady_clock::now();
  auto* root = static_cast<EmbreeNode*>(rtcBuildBVH(&args));
  const auto t1 = std::chrono::steady_clock::now();
  if (!root) throw std::runtime_error("embree: rtcBuildBVH failed");
  r.build_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  TreeSums sums;
  sum_tree(root, impl_->scene_bounds, 0, sums);
  const double root_area = impl_->scene_bounds.half_area();
  r.sah_cost = root_area > 0 ? sums.sah / root_area : 0.0;
  r.nodes = sums.nodes;
  r.leaves = sums.leaves;
  r.depth = sums.depth;
  return r;
}

}  // namespace hprt::bench
