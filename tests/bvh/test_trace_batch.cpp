// The batch entry points (bvh/traverse/trace_batch.h) of every layout and
// triangle test answer each ray exactly as the single-ray traversal does,
// packets included (coherent grids make full coherent groups), and write
// nothing past the batch; invalid rays miss.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <vector>

#include "bvh/intersect/ray_triangle.h"
#include "bvh/layout/flatten_wide.h"
#include "bvh/traverse/trace_batch.h"
#include "bvh/traverse/traverse_all.h"
#include "bvh/traverse/traverse_bvh2.h"
#include "bvh/traverse/traverse_point.h"
#include "bvh/traverse/traverse_wide.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

template <typename Test>
Hit one_ray(const Bvh2& bvh, const Ray& r) {
  Hit h;
  if (ray_is_valid(r)) traverse<Test, false>(bvh, r, h);
  return h;
}
template <typename Test, int N>
Hit one_ray(const WideBvh<N>& bvh, const Ray& r) {
  Hit h;
  if (ray_is_valid(r)) traverse_wide<Test, false>(bvh, r, h);
  return h;
}

template <typename Test, typename Bvh>
void expect_batch_equals_single_rays(const Bvh& bvh, TriangleTestKind kind,
                                     const std::vector<Ray>& rays) {
  // One slot more than the batch, to catch a write past its end.
  std::vector<Hit> hits(rays.size() + 1);
  Hit sentinel;
  sentinel.t = 42.0f;
  hits.back() = sentinel;
  intersect_batch(bvh, kind, rays, hits.data());
  std::vector<uint8_t> occ(rays.size() + 1, 7);
  occluded_batch(bvh, kind, rays, occ.data());
  size_t hit_count = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Hit want = one_ray<Test>(bvh, rays[i]);
    ASSERT_TRUE(test::same_hit(hits[i], want)) << "ray " << i;
    EXPECT_EQ(occ[i], want.hit() ? 1 : 0) << "ray " << i;
    hit_count += want.hit();
  }
  EXPECT_TRUE(test::same_hit(hits.back(), sentinel));
  EXPECT_EQ(occ.back(), 7);
  EXPECT_GT(hit_count, rays.size() / 10);  // the rays do meet the mesh
}

template <typename Test>
void check_every_layout(TriangleTestKind kind) {
  test::BuiltBvh b = test::build_flat({generate_sphere(5000), test::random_soup(3000, 5)}, {});
  const AABB box = b.scene.bounds();
  std::vector<Ray> rays = test::coherent_rays(box, 64, 48);  // full coherent groups
  const std::vector<Ray> random = test::random_rays(box, 3001, 9);
  rays.insert(rays.end(), random.begin(), random.end());
  rays[5].dir = Vec3f(0.0f);                                   // invalid in a packet group
  rays[4000].org.x = std::numeric_limits<float>::quiet_NaN();  // invalid on its own
  expect_batch_equals_single_rays<Test>(b.bvh, kind, rays);
  expect_batch_equals_single_rays<Test>(flatten_wide<4>(b.tree, b.prims, b.scene), kind, rays);
  expect_batch_equals_single_rays<Test>(flatten_wide<8>(b.tree, b.prims, b.scene), kind, rays);
}

TEST(TraceBatch, WatertightEqualsSingleRaysInEveryLayout) {
  check_every_layout<WatertightTest>(TriangleTestKind::kWatertight);
}

TEST(TraceBatch, MollerEqualsSingleRaysInEveryLayout) {
  check_every_layout<MollerTest>(TriangleTestKind::kMoller);
}

// Wide trees of at least kInterleaveMinBytes trace the rays no packet takes
// several at a time (traverse_interleaved.h): the same answers.
TEST(TraceBatch, LargeTreeTracedInterleavedEqualsSingleRays) {
  test::BuiltBvh b = test::build_flat({generate_bumpy_sphere(320000, 3)}, {});
  const AABB box = b.scene.bounds();
  std::vector<Ray> rays = test::random_rays(box, 4001, 13);
  const std::vector<Ray> coherent = test::coherent_rays(box, 32, 16);
  rays.insert(rays.end(), coherent.begin(), coherent.end());
  rays[7].dir = Vec3f(0.0f);
  rays[100].tfar = 0.0f;
  for (const auto arrays : {TriangleArrays::kVerts, TriangleArrays::kEdges}) {
    const auto bvh8 = flatten_wide<8>(b.tree, b.prims, b.scene, arrays);
    const auto bvh4 = flatten_wide<4>(b.tree, b.prims, b.scene, arrays);
    ASSERT_GE(bvh8.memory_bytes(), kInterleaveMinBytes);
    ASSERT_GE(bvh4.memory_bytes(), kInterleaveMinBytes);
    if (arrays == TriangleArrays::kVerts) {
      expect_batch_equals_single_rays<WatertightTest>(bvh8, TriangleTestKind::kWatertight, rays);
      expect_batch_equals_single_rays<WatertightTest>(bvh4, TriangleTestKind::kWatertight, rays);
    } else {
      expect_batch_equals_single_rays<MollerTest>(bvh8, TriangleTestKind::kMoller, rays);
      expect_batch_equals_single_rays<MollerTest>(bvh4, TriangleTestKind::kMoller, rays);
    }
  }
}

// The count, all and inside queries of such a tree trace several rays at a
// time too (traverse_all_interleaved.h): the same counts and hit lists
// (bounded or not) as traverse_all ray by ray, the same locations as
// locate_point point by point (random points, points exactly on the
// surface, invalid points and rays).
TEST(TraceBatch, LargeTreeCountsListsAndLocatesInterleavedAsOneByOne) {
  test::BuiltBvh b = test::build_flat({generate_bumpy_sphere(320000, 3)}, {});
  const AABB box = b.scene.bounds();
  std::vector<Ray> rays = test::random_rays(box, 3001, 17);
  rays[5].dir = Vec3f(0.0f);
  rays[9].tfar = 0.0f;
  rays[11].tfar = 0.5f * length(box.diagonal());
  std::vector<Vec3f> points;
  test::Rng rng(23);
  for (int i = 0; i < 2000; ++i) {
    Vec3f p;
    for (int a = 0; a < 3; ++a)
      p[a] = box.min[a] + float(rng.uniform()) * (box.max[a] - box.min[a]);
    points.push_back(p);
  }
  const auto& verts = b.scene.meshes[0].positions;
  for (size_t i = 0; i < verts.size(); i += verts.size() / 300) points.push_back(verts[i]);
  points.push_back(Vec3f(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
  for (const auto arrays : {TriangleArrays::kVerts, TriangleArrays::kEdges}) {
    const auto bvh8 = flatten_wide<8>(b.tree, b.prims, b.scene, arrays);
    ASSERT_GE(bvh8.memory_bytes(), kInterleaveMinBytes);
    const TriangleTestKind kind = arrays == TriangleArrays::kVerts ? TriangleTestKind::kWatertight
                                                                   : TriangleTestKind::kMoller;
    std::vector<uint32_t> counts(rays.size(), 77);
    count_batch(bvh8, kind, rays, counts.data());
    size_t crossed = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      uint32_t want = 0;
      const auto one = [&](const LeafRange&, uint32_t, const TriangleHit&) { ++want; };
      if (ray_is_valid(rays[i])) {
        if (kind == TriangleTestKind::kWatertight)
          traverse_all<WatertightTest>(bvh8, rays[i], one);
        else
          traverse_all<MollerTest>(bvh8, rays[i], one);
      }
      ASSERT_EQ(counts[i], want) << "ray " << i;
      crossed += want > 0;
    }
    EXPECT_GT(crossed, rays.size() / 10);
    // Every hit, nearest first: the counts' hits, cut at a bound of 2.
    for (const uint32_t bound : {1024u, 2u}) {
      HitLists lists;
      all_batch(bvh8, kind, rays, bound, lists);
      ASSERT_EQ(lists.rays(), rays.size());
      for (size_t i = 0; i < rays.size(); ++i) {
        std::vector<Hit> want;
        const auto one = [&](const LeafRange&, uint32_t t, const TriangleHit& h) {
          want.push_back(
              Hit{h.t, h.u, h.v, bvh8.triangles.refs[t].geom_id, bvh8.triangles.refs[t].prim_id});
        };
        if (ray_is_valid(rays[i])) {
          if (kind == TriangleTestKind::kWatertight)
            traverse_all<WatertightTest>(bvh8, rays[i], one);
          else
            traverse_all<MollerTest>(bvh8, rays[i], one);
        }
        std::sort(want.begin(), want.end(), hit_list_before);
        ASSERT_EQ(lists.truncated[i], want.size() > bound ? 1 : 0) << "ray " << i;
        want.resize(std::min<size_t>(want.size(), bound));
        ASSERT_EQ(lists.count(i), want.size()) << "ray " << i;
        for (size_t k = 0; k < want.size(); ++k)
          ASSERT_TRUE(test::same_hit(lists.hits[lists.offsets[i] + k], want[k])) << "ray " << i;
      }
    }
    if (kind != TriangleTestKind::kWatertight) continue;  // inside reads exact vertices
    std::vector<PointLocation> where(points.size(), PointLocation(9));
    locate_batch(bvh8, points, where.data());
    size_t inside = 0, on = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const PointLocation want =
          i + 1 == points.size() ? PointLocation::kOutside : locate_point(bvh8, points[i]);
      ASSERT_EQ(where[i], want) << "point " << i;
      inside += want == PointLocation::kInside;
      on += want == PointLocation::kOnSurface;
    }
    EXPECT_GT(inside, 100u);
    EXPECT_GT(on, 100u);
  }
}

TEST(TraceBatch, EmptyBatchAndEmptyTree) {
  test::BuiltBvh none = test::build_flat({}, {});
  std::vector<Ray> rays = test::random_rays(AABB(Vec3f(0.0f), Vec3f(1.0f)), 40, 1);
  std::vector<Hit> hits(rays.size());
  intersect_batch(none.bvh, TriangleTestKind::kWatertight, rays, hits.data());
  for (const Hit& h : hits) EXPECT_FALSE(h.hit());
  intersect_batch(none.bvh, TriangleTestKind::kWatertight, std::span<const Ray>(), nullptr);
  std::vector<uint8_t> occ(rays.size(), 1);
  occluded_batch(flatten_wide<8>(none.tree, none.prims, none.scene), TriangleTestKind::kWatertight,
                 rays, occ.data());
  for (uint8_t o : occ) EXPECT_EQ(o, 0);
}

}  // namespace
}  // namespace hprt
