// Several rays in flight (bvh/traverse/traverse_interleaved.h) answer each
// ray bit for bit as traverse_wide does alone, closest and any hit, and
// report every hit of each ray as traverse_all does
// (traverse_all_interleaved.h), in both wide layouts and for both triangle
// tests, also as columns with the hit normals (the scene's own triangle's,
// from the vertices or the leaf-order table): whatever order and number of
// rays it is given (fewer than the slots, one, none), with invalid rays,
// bounded intervals, a tree that is a single leaf, and rays that end while
// others are still in flight. It writes exactly the rays it is given.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <numeric>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "bvh/intersect/ray_triangle.h"
#include "bvh/layout/flatten_wide.h"
#include "bvh/traverse/traverse_all.h"
#include "bvh/traverse/traverse_all_interleaved.h"
#include "bvh/traverse/traverse_interleaved.h"
#include "bvh/traverse/traverse_wide.h"
#include "core/triangle_normal.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

// Random rays with some made invalid and some with bounded, shifted
// intervals, so rays end after very different numbers of turns.
std::vector<Ray> mixed_rays(const AABB& box, size_t n, uint64_t seed) {
  std::vector<Ray> rays = test::random_rays(box, n, seed);
  const float d = length(box.diagonal());
  for (size_t i = 0; i < rays.size(); ++i) {
    if (i % 37 == 5) rays[i].dir = Vec3f(0.0f);
    if (i % 41 == 7) rays[i].org.y = std::numeric_limits<float>::quiet_NaN();
    if (i % 5 == 1) rays[i].tfar = 0.3f * d;
    if (i % 7 == 2) rays[i].tnear = 0.2f * d;
  }
  return rays;
}

// The leaf-order normal table HitColumnWriter reads for trees without vertices.
template <int N>
std::vector<float> normal_table(const WideBvh<N>& bvh, const Scene& scene) {
  std::vector<float> table(3 * bvh.triangles.size());
  for (size_t i = 0; i < bvh.triangles.size(); ++i) {
    const PrimRef& r = bvh.triangles.refs[i];
    triangle_normal(scene.meshes[r.geom_id], r.prim_id, &table[3 * i]);
  }
  return table;
}

// Closest hits as records and as columns with normals (the same answers),
// and any hits, of the rays in `order`: each as traverse_wide alone answers
// it, the normal that of the scene's own triangle (bit for bit), zero on a
// miss; nothing written for the other rays.
template <typename Test, int N>
void expect_same_as_alone(const WideBvh<N>& bvh, const Scene& scene, const std::vector<Ray>& rays,
                          const std::vector<size_t>& order) {
  const Hit sentinel{42.0f, 0.5f, 0.5f, 7, 7};
  std::vector<Hit> hits(rays.size(), sentinel);
  std::vector<uint8_t> occluded(rays.size(), 9);
  traverse_wide_interleaved<Test, false>(bvh, rays.data(), order.data(), order.size(), hits.data(),
                                         nullptr);
  const bool has_verts = bvh.triangles.holds(TriangleArrays::kVerts);
  const std::vector<float> table = has_verts ? std::vector<float>() : normal_table(bvh, scene);
  std::vector<float> t(rays.size(), 5.0f), uv(2 * rays.size(), 5.0f),
      normals(3 * rays.size(), 5.0f);
  std::vector<uint32_t> geom(rays.size(), 5), prim(rays.size(), 5);
  const HitColumnWriter out{{t.data(), geom.data(), prim.data(), uv.data(), normals.data()},
                            &bvh.triangles,
                            has_verts ? nullptr : table.data()};
  traverse_wide_interleaved<Test, false>(bvh, rays.data(), order.data(), order.size(), nullptr,
                                         nullptr, &out);
  traverse_wide_interleaved<Test, true>(bvh, rays.data(), order.data(), order.size(), nullptr,
                                        occluded.data());
  std::vector<bool> given(rays.size(), false);
  for (size_t i : order) given[i] = true;
  size_t hit_count = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const float* n = &normals[3 * i];
    const Hit column{t[i], uv[2 * i], uv[2 * i + 1], geom[i], prim[i]};
    if (!given[i]) {  // untouched
      ASSERT_TRUE(test::same_hit(hits[i], sentinel)) << "ray " << i;
      ASSERT_TRUE(test::same_hit(column, Hit{5.0f, 5.0f, 5.0f, 5, 5})) << "ray " << i;
      ASSERT_EQ(occluded[i], 9) << "ray " << i;
      ASSERT_TRUE(n[0] == 5.0f && n[1] == 5.0f && n[2] == 5.0f) << "ray " << i;
      continue;
    }
    Hit want, any;
    const bool valid = ray_is_valid(rays[i]);
    if (valid) traverse_wide<Test, false>(bvh, rays[i], want);
    const bool occ = valid && traverse_wide<Test, true>(bvh, rays[i], any);
    ASSERT_TRUE(test::same_hit(hits[i], want)) << "ray " << i;
    ASSERT_TRUE(test::same_hit(column, want)) << "ray " << i;
    float expected[3] = {0.0f, 0.0f, 0.0f};
    if (want.hit()) triangle_normal(scene.meshes[want.geom_id], want.prim_id, expected);
    ASSERT_EQ(std::memcmp(n, expected, sizeof expected), 0)
        << "ray " << i << ": " << n[0] << " " << n[1] << " " << n[2];
    ASSERT_EQ(occluded[i], occ ? 1 : 0) << "ray " << i;
    hit_count += want.hit();
  }
  if (order.size() > 100) {
    EXPECT_GT(hit_count, order.size() / 10);  // the rays do meet the mesh
  }
}

// Every hit of traverse_all_interleaved over rays [first, first + count):
// the same (leaf index, t, u, v) per ray as traverse_all's, in any order,
// with each ray's own tnear and with one lower end for every leaf test;
// nothing for rays outside the range or invalid.
using Visit = std::tuple<uint32_t, float, float, float>;
template <typename Test, int N>
void expect_all_hits_as_alone(const WideBvh<N>& bvh, const std::vector<Ray>& rays, size_t first,
                              size_t count) {
  for (const std::optional<float> leaf_tnear :
       {std::optional<float>(), std::optional<float>(-std::numeric_limits<float>::infinity())}) {
    std::vector<std::vector<Visit>> got(rays.size());
    traverse_all_interleaved<Test>(
        bvh, rays.data(), first, count,
        [&](size_t i, const LeafRange&, uint32_t k, const TriangleHit& h) {
          got[i].emplace_back(k, h.t, h.u, h.v);
        },
        leaf_tnear);
    size_t visits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      std::vector<Visit> want;
      if (i >= first && i < first + count && ray_is_valid(rays[i]))
        traverse_all<Test>(
            bvh, rays[i],
            [&](const LeafRange&, uint32_t k, const TriangleHit& h) {
              want.emplace_back(k, h.t, h.u, h.v);
            },
            leaf_tnear.value_or(rays[i].tnear));
      std::sort(want.begin(), want.end());
      std::sort(got[i].begin(), got[i].end());
      ASSERT_EQ(got[i], want) << "ray " << i;
      visits += want.size();
    }
    if (count > 100) {
      EXPECT_GT(visits, count / 10);
    }
  }
}

template <typename Test>
void check_layouts(const std::vector<TriangleMesh>& meshes, TriangleArrays arrays) {
  test::BuiltBvh b = test::build_flat(meshes, {});
  const std::vector<Ray> rays = mixed_rays(b.scene.bounds(), 2000, 3);
  std::vector<size_t> all(rays.size());
  std::iota(all.begin(), all.end(), size_t{0});
  std::vector<size_t> shuffled = all;
  test::Rng rng(11);
  for (size_t i = shuffled.size(); i > 1; --i)
    std::swap(shuffled[i - 1], shuffled[size_t(rng.uniform() * double(i)) % i]);
  std::vector<size_t> few = {17, 3, 1999};  // fewer rays than slots
  std::vector<size_t> none;
  const auto bvh4 = flatten_wide<4>(b.tree, b.prims, b.scene, arrays);
  const auto bvh8 = flatten_wide<8>(b.tree, b.prims, b.scene, arrays);
  for (const auto* order : {&all, &shuffled, &few, &none}) {
    expect_same_as_alone<Test>(bvh4, b.scene, rays, *order);
    expect_same_as_alone<Test>(bvh8, b.scene, rays, *order);
  }
  // Every hit: all rays, a range inside the batch, fewer rays than slots, none.
  for (const auto& [first, count] :
       {std::pair<size_t, size_t>{0, rays.size()}, {300, 901}, {1995, 3}, {10, 0}}) {
    expect_all_hits_as_alone<Test>(bvh4, rays, first, count);
    expect_all_hits_as_alone<Test>(bvh8, rays, first, count);
  }
}

TEST(TraverseInterleaved, WatertightSameAsAloneOnSphereAndSoup) {
  check_layouts<WatertightTest>({generate_sphere(6000), test::random_soup(4000, 5)},
                                TriangleArrays::kVerts);
}

TEST(TraverseInterleaved, MollerSameAsAloneOnSphereAndSoup) {
  check_layouts<MollerTest>({generate_sphere(6000), test::random_soup(4000, 5)},
                            TriangleArrays::kEdges);
}

TEST(TraverseInterleaved, SliversWhereRaysVisitManyNodes) {
  check_layouts<WatertightTest>({generate_sliver_sheet(3000, 2)}, TriangleArrays::kVerts);
}

TEST(TraverseInterleaved, TreeThatIsOneLeaf) {
  // Two triangles: the root is a leaf, so every ray's first turn is a leaf.
  check_layouts<WatertightTest>({generate_sphere(2)}, TriangleArrays::kVerts);
}

}  // namespace
}  // namespace hprt
