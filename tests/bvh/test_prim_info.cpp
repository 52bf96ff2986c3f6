// Tests of make_prim_info: valid triangles only, refs, boxes, centroids, bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "bvh/builders/builders.h"
#include "bvh/input/prim_info.h"
#include "core/parallel.h"
#include "tests/support/bvh_test_meshes.h"

namespace hprt::test {
namespace {

TEST(PrimInfo, KeepsValidTrianglesWithTheirRefs) {
  Scene s;
  s.add_mesh(with_invalid_triangles());
  s.add_mesh(random_soup(3, 1));
  const PrimInfo p = make_prim_info(s);
  ASSERT_EQ(p.size(), 9u);
  EXPECT_EQ(p.invalid, 5u);
  const std::vector<PrimRef> want = {{0, 0},  {0, 2}, {0, 4}, {0, 6}, {0, 8},
                                     {0, 10}, {1, 0}, {1, 1}, {1, 2}};
  EXPECT_EQ(std::vector<PrimRef>(p.refs.begin(), p.refs.end()), want);
  EXPECT_EQ(p.bounds[1], AABB({2, 0, 0}, {3, 1, 0}));
  EXPECT_EQ(p.centroids[1], (Vec3f{2.5f, 0.5f, 0.0f}));
  AABB sb, cb;
  for (size_t i = 0; i < p.size(); ++i) {
    sb.extend(p.bounds[i]);
    cb.extend(p.centroids[i]);
  }
  EXPECT_EQ(p.scene_bounds, sb);
  EXPECT_EQ(p.centroid_bounds, cb);
}

// A soup of n triangles of which every `every`-th is degenerate, beside a
// grid of g x g cells.
Scene soup_with_gaps_and_grid(size_t n, uint64_t seed, size_t every, int g) {
  Scene s;
  TriangleMesh m = random_soup(n, seed);
  for (size_t i = 0; i < m.triangles.size(); i += every) m.triangles[i][1] = m.triangles[i][0];
  s.add_mesh(m);
  s.add_mesh(grid(g, g));
  return s;
}

TEST(PrimInfo, SameResultForAnyThreadCount) {
  const Scene s = soup_with_gaps_and_grid(100000, 2, 97, 50);
  const PrimInfo one = run_with_threads(1, [&] { return make_prim_info(s); });
  const PrimInfo many = run_with_threads(7, [&] { return make_prim_info(s); });
  EXPECT_EQ(one.invalid, (100000 + 96) / 97);
  EXPECT_EQ(one.size(), 100000 + 5000 - one.invalid);
  EXPECT_EQ(one.bounds, many.bounds);
  EXPECT_EQ(one.centroids, many.centroids);
  EXPECT_EQ(one.refs, many.refs);
  EXPECT_EQ(one.scene_bounds, many.scene_bounds);
  EXPECT_EQ(one.centroid_bounds, many.centroid_bounds);
}

// Invalid triangles in many chunks (one chunk all invalid, a mesh all
// invalid): the gaps they leave are closed, everything in input order.
TEST(PrimInfo, MatchesASequentialReferenceAcrossChunks) {
  Scene s;
  TriangleMesh a = random_soup(60000, 3);
  for (size_t i = 0; i < a.triangles.size(); i += 61) a.triangles[i][2] = a.triangles[i][0];
  for (size_t i = 16384; i < 40000; ++i) a.triangles[i][1] = a.triangles[i][0];  // chunk 1 whole
  TriangleMesh dead = random_soup(5, 4);
  for (auto& t : dead.triangles) t[1] = t[0];
  s.add_mesh(a);
  s.add_mesh(dead);
  s.add_mesh(grid(120, 120));
  std::vector<AABB> bounds;
  std::vector<Vec3f> centroids;
  std::vector<PrimRef> refs;
  for (size_t g = 0; g < s.meshes.size(); ++g) {
    const TriangleMesh& m = s.meshes[g];
    for (size_t i = 0; i < m.triangle_count(); ++i) {
      if (!m.triangle_valid(i)) continue;
      AABB b;
      for (int k = 0; k < 3; ++k) b.extend(m.positions[m.triangles[i][k]]);
      bounds.push_back(b);
      centroids.push_back(b.center());
      refs.push_back({uint32_t(g), uint32_t(i)});
    }
  }
  const PrimInfo p = run_with_threads(2, [&] { return make_prim_info(s); });
  EXPECT_EQ(p.invalid, 60000 + 5 + 2 * 120 * 120 - refs.size());
  EXPECT_GT(p.invalid, 20000u);
  EXPECT_EQ(std::vector<AABB>(p.bounds.begin(), p.bounds.end()), bounds);
  EXPECT_EQ(std::vector<Vec3f>(p.centroids.begin(), p.centroids.end()), centroids);
  EXPECT_EQ(std::vector<PrimRef>(p.refs.begin(), p.refs.end()), refs);
}

// Without stored centroids (the binned and parallel builders' input) the
// boxes, refs and both bounds are the same, the centroid array is empty,
// those builders make the same trees, and the builders that read centroids
// refuse it.
TEST(PrimInfo, WithoutCentroidsTheRestIsTheSame) {
  const Scene s = soup_with_gaps_and_grid(40000, 5, 53, 30);
  const PrimInfo full = run_with_threads(2, [&] { return make_prim_info(s); });
  const PrimInfo lean = run_with_threads(2, [&] { return make_prim_info(s, false); });
  EXPECT_EQ(lean.centroids.size(), 0u);
  EXPECT_EQ(lean.bounds, full.bounds);
  EXPECT_EQ(lean.refs, full.refs);
  EXPECT_EQ(lean.invalid, full.invalid);
  EXPECT_EQ(lean.scene_bounds, full.scene_bounds);
  EXPECT_EQ(lean.centroid_bounds, full.centroid_bounds);
  for (BuilderKind b : {BuilderKind::kSweep, BuilderKind::kPresorted, BuilderKind::kBinned,
                        BuilderKind::kParallel, BuilderKind::kMorton}) {
    BuildOptions o;
    o.builder = b;
    if (builder_reads_centroids(b)) {
      EXPECT_THROW(build_tree(lean, o), std::invalid_argument);
    } else {
      EXPECT_EQ(run_with_threads(2, [&] { return build_tree(lean, o); }),
                run_with_threads(2, [&] { return build_tree(full, o); }));
    }
  }
  EXPECT_FALSE(builder_reads_centroids(BuilderKind::kMorton));
  EXPECT_FALSE(builder_reads_centroids(BuilderKind::kParallel));
}

TEST(PrimInfo, EmptyScene) {
  const PrimInfo p = make_prim_info(Scene{});
  EXPECT_EQ(p.size(), 0u);
  EXPECT_EQ(p.invalid, 0u);
  EXPECT_TRUE(p.scene_bounds.empty());
}

// The fill (16 triangles at a time where AVX-512 is there) against the
// definition, one triangle at a time, bit for bit: triangle_valid, then the
// box of three extends and its centre. The mesh mixes signed zeros,
// subnormals, huge and tiny coordinates, NaN and infinite vertices, indices
// out of range, repeated and collinear vertices and nearly degenerate
// triangles (nonzero area only in the double products), at positions that
// spoil some 16-triangle groups and leave others whole.
TEST(PrimInfo, FillMatchesTheOneTriangleDefinitionBitForBit) {
  std::mt19937 rng(11);
  const float specials[] = {0.0f, -0.0f, 1e-45f, -1e-45f, 1e-38f, 3.4e38f,     -3.4e38f,
                            1.0f, -1.0f, 0.5f,   1e-7f,   1e7f,   16777216.0f, 1.0e-3f};
  TriangleMesh m;
  std::vector<Vec3f> pos;
  std::uniform_int_distribution<int> pick(0, 13), kind(0, 9);
  std::uniform_real_distribution<float> uni(-2.0f, 2.0f);
  for (int v = 0; v < 3000; ++v) {
    const auto c = [&] { return kind(rng) < 3 ? specials[pick(rng)] : uni(rng); };
    pos.push_back({c(), c(), c()});
  }
  pos[17] = {std::numeric_limits<float>::quiet_NaN(), 0, 0};
  pos[99] = {0, std::numeric_limits<float>::infinity(), 0};
  m.positions = pos;
  std::vector<Vec3u> tris;
  std::uniform_int_distribution<uint32_t> vert(0, 2999);
  for (uint32_t t = 0; t < 40000; ++t) {
    Vec3u tri{vert(rng), vert(rng), vert(rng)};
    const int k = kind(rng);
    if (t % 997 == 5 && k < 3) tri[k] = 3000 + t;  // out of range
    if (t % 211 == 7) tri[1] = tri[0];             // repeated vertex
    if (t % 401 == 3) tri[2] = 17;                 // NaN vertex
    if (t % 389 == 4) tri[0] = 99;                 // infinite vertex
    tris.push_back(tri);
  }
  // Nearly degenerate: the products of the edge components differ only in
  // double (c is a + (b - a) * (1 + 2^-23) in one coordinate).
  const uint32_t base = static_cast<uint32_t>(pos.size());
  for (int k = 0; k < 64; ++k) {
    const Vec3f a{1.0f + k, 2.0f, 3.0f}, b{2.0f + k, 4.0f, 6.0f};
    const Vec3f c{3.0f + k, 6.0f, k % 2 ? 9.0f : std::nextafter(9.0f, 10.0f)};
    pos.push_back(a), pos.push_back(b), pos.push_back(c);
    tris.push_back({base + 3u * k, base + 3u * k + 1, base + 3u * k + 2});
  }
  m.positions = pos;
  m.triangles = tris;
  Scene s;
  s.add_mesh(m);
  s.add_mesh(grid(40, 40));
  for (bool centroids : {true, false}) {
    const PrimInfo p = run_with_threads(2, [&] { return make_prim_info(s, centroids); });
    size_t w = 0, invalid = 0;
    for (uint32_t g = 0; g < s.meshes.size(); ++g)
      for (size_t i = 0; i < s.meshes[g].triangle_count(); ++i) {
        const TriangleMesh& mesh = s.meshes[g];
        if (!mesh.triangle_valid(i)) {
          ++invalid;
          continue;
        }
        AABB box;
        for (int k = 0; k < 3; ++k) box.extend(mesh.positions[mesh.triangles[i][k]]);
        ASSERT_LT(w, p.size());
        ASSERT_EQ(std::memcmp(&p.bounds[w], &box, sizeof box), 0) << "mesh " << g << " tri " << i;
        if (centroids) {
          const Vec3f c = box.center();
          ASSERT_EQ(std::memcmp(&p.centroids[w], &c, sizeof c), 0) << "tri " << i;
        }
        ASSERT_EQ(p.refs[w], (PrimRef{g, static_cast<uint32_t>(i)}));
        ++w;
      }
    EXPECT_EQ(w, p.size());
    EXPECT_EQ(invalid, p.invalid);
    EXPECT_GT(invalid, 500u);
    EXPECT_GT(p.size(), 30000u);
  }
}

}  // namespace
}  // namespace hprt::test
