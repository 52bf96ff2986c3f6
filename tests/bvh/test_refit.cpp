// Refit (bvh/refit/refit_bvh2.h): after any deformation every node box is exactly the
// union of its children (leaves: of their triangles, re-gathered from the
// scene), the SAH cost of the flat tree equals compute_tree_stats' right after
// a build, the result does not depend on the thread count, an invalidated
// triangle is reported, and a refit allocates nothing.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "anim/scene_animator.h"
#include "bvh/builders/builders.h"
#include "bvh/layout/flatten_bvh2.h"
#include "bvh/layout/flatten_wide.h"
#include "bvh/refit/refit_bvh2.h"
#include "bvh/refit/refit_wide.h"
#include "core/parallel.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/bvh_test_meshes.h"
#include "tests/support/wide_bvh_checks.h"

// Counting global operator new: refit must not allocate (counted only while
// g_counting is set, on every thread).
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
void* counted_alloc(std::size_t n, std::size_t align) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (n == 0) n = 1;
  void* p = align > alignof(std::max_align_t)
                ? std::aligned_alloc(align, (n + align - 1) / align * align)
                : std::malloc(n);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace
// Not inlined: inlined into a `new T` / `delete` pair, g++ 12 sees free() of
// malloc's pointer, or operator delete of malloc's, and warns
// (-Wmismatched-new-delete).
[[gnu::noinline]] void* operator new(std::size_t n) { return counted_alloc(n, 0); }
[[gnu::noinline]] void* operator new[](std::size_t n) { return counted_alloc(n, 0); }
[[gnu::noinline]] void* operator new(std::size_t n, std::align_val_t a) {
  return counted_alloc(n, size_t(a));
}
[[gnu::noinline]] void* operator new[](std::size_t n, std::align_val_t a) {
  return counted_alloc(n, size_t(a));
}
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete[](void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

namespace hprt {
namespace {

constexpr int kThreads = 2;

Bvh2 build_flat(const Scene& scene, BuilderKind builder, TreeStats* stats = nullptr) {
  BuildOptions o;
  o.builder = builder;
  const PrimInfo prims = make_prim_info(scene);
  const BuildTree tree = build_tree(prims, o);
  if (stats) *stats = compute_tree_stats(tree, prims);
  return flatten(tree, prims, scene);
}

// "" when every node box is exactly the union of its children (leaves: of
// their triangles), every leaf triangle holds the scene's current vertices,
// and the leaves cover every triangle once; else the first violation.
std::string check_flat(const Bvh2& bvh, const Scene& scene) {
  if (bvh.empty()) return "";
  std::vector<int> covered(bvh.triangles.size(), 0);
  std::string err;
  auto box_of = [](const BinaryNode& n) { return AABB(n.min, n.max); };
  auto walk = [&](auto&& self, uint32_t i, int depth) -> void {
    if (!err.empty()) return;
    if (i >= bvh.nodes.size() || depth > kMaxBuildDepth) {
      err = "bad node index or depth";
      return;
    }
    const BinaryNode& n = bvh.nodes[i];
    AABB u;
    if (n.is_leaf()) {
      for (uint32_t j = n.index; j < n.index + n.count; ++j) {
        if (j >= covered.size() || covered[j]++) {
          err = "leaf range out of range or overlapping";
          return;
        }
        const PrimRef r = bvh.triangles.refs[j];
        const TriangleMesh& m = scene.meshes[r.geom_id];
        const Vec3u& t = m.triangles[r.prim_id];
        const TriangleVerts v = bvh.triangles.triangle(LeafRange::whole(n.index, n.count), j);
        const TriangleEdges& e = bvh.triangles.edges[j];
        if (!(v.v0 == m.positions[t[0]] && v.v1 == m.positions[t[1]] &&
              v.v2 == m.positions[t[2]]) ||
            !(e.v0 == v.v0 && e.e1 == v.v1 - v.v0 && e.e2 == v.v2 - v.v0)) {
          err = "stale triangle data at " + std::to_string(j);
          return;
        }
        AABB tb;
        tb.extend(v.v0);
        tb.extend(v.v1);
        tb.extend(v.v2);
        if (!box_of(n).contains(tb))
          err = "leaf box misses a triangle at node " + std::to_string(i);
        u.extend(tb);
      }
    } else {
      self(self, n.index, depth + 1);
      self(self, n.index + 1, depth + 1);
      if (!err.empty()) return;
      const AABB l = box_of(bvh.nodes[n.index]), r = box_of(bvh.nodes[n.index + 1]);
      if (!box_of(n).contains(l) || !box_of(n).contains(r))
        err = "inner box misses a child at node " + std::to_string(i);
      u = l;
      u.extend(r);
    }
    if (err.empty() && !(u == box_of(n))) err = "box not tight at node " + std::to_string(i);
  };
  walk(walk, 0, 1);
  if (!err.empty()) return err;
  for (int c : covered)
    if (c != 1) return "a triangle is in no leaf";
  return "";
}

Scene soup_scene(size_t n = 20000) {
  Scene s;
  s.add_mesh(test::random_soup(n, 7));
  return s;
}

TEST(Refit, SahCostMatchesTreeStatsAfterBuild) {
  run_with_threads(kThreads, [] {
    for (BuilderKind b : {BuilderKind::kSweep, BuilderKind::kPresorted, BuilderKind::kBinned,
                          BuilderKind::kParallel, BuilderKind::kMorton}) {
      for (int mesh = 0; mesh < 3; ++mesh) {
        Scene s;
        if (mesh == 0) s.add_mesh(test::random_soup(5000, 3));
        if (mesh == 1) s.add_mesh(generate_sphere(5000));
        if (mesh == 2) s.add_mesh(test::with_invalid_triangles());
        TreeStats stats;
        const Bvh2 bvh = build_flat(s, b, &stats);
        const double flat = bvh2_sah_cost(bvh);
        EXPECT_NEAR(flat, stats.sah_cost, 1e-12 * stats.sah_cost)
            << to_string(b) << " mesh " << mesh;
        EXPECT_GT(flat, 1.0);
        // Refit of an unmoved scene: same boxes bit for bit, same cost.
        Bvh2 refitted = bvh;
        const RefitResult r = refit(refitted, s);
        EXPECT_TRUE(r.valid);
        EXPECT_NEAR(r.sah_cost, stats.sah_cost, 1e-12 * stats.sah_cost);
        ASSERT_EQ(refitted.nodes.size(), bvh.nodes.size());
        for (size_t i = 0; i < bvh.nodes.size(); ++i) {
          EXPECT_EQ(refitted.nodes[i].min, bvh.nodes[i].min) << i;
          EXPECT_EQ(refitted.nodes[i].max, bvh.nodes[i].max) << i;
          EXPECT_EQ(refitted.nodes[i].index, bvh.nodes[i].index) << i;
          EXPECT_EQ(refitted.nodes[i].count, bvh.nodes[i].count) << i;
        }
      }
    }
  });
}

TEST(Refit, EmptyAndSingleLeafTrees) {
  Scene empty;
  Bvh2 none;
  EXPECT_TRUE(refit(none, empty).valid);
  EXPECT_EQ(bvh2_sah_cost(none), 0.0);
  Scene one;
  TriangleMesh m;
  test::add_triangle(m, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  one.add_mesh(m);
  Bvh2 bvh = build_flat(one, BuilderKind::kBinned);
  ASSERT_EQ(bvh.nodes.size(), 1u);
  one.meshes[0].positions[1] = {5, 0, 0};
  const RefitResult r = refit(bvh, one);
  EXPECT_TRUE(r.valid);
  EXPECT_EQ(r.sah_cost, 1.0);  // one leaf of one triangle, weight 1
  EXPECT_EQ(bvh.nodes[0].max.x, 5.0f);
  EXPECT_EQ(check_flat(bvh, one), "");
}

TEST(Refit, RandomJitterKeepsBoxesTight) {
  Scene s = soup_scene();
  Bvh2 bvh = build_flat(s, BuilderKind::kParallel);
  test::Rng rng(5);
  for (int frame = 0; frame < 4; ++frame) {
    for (Vec3f& p : s.meshes[0].positions)
      p += Vec3f{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f} * 0.05f;
    const RefitResult r = run_with_threads(kThreads, [&] { return refit(bvh, s); });
    EXPECT_TRUE(r.valid);
    EXPECT_NEAR(r.sah_cost, bvh2_sah_cost(bvh), 1e-12 * r.sah_cost);
    ASSERT_EQ(check_flat(bvh, s), "") << "frame " << frame;
  }
}

TEST(Refit, LargeMotionKeepsBoxesTight) {
  Scene s;
  s.add_mesh(generate_sphere(20000));
  s.add_mesh(test::random_soup(3000, 9));
  Bvh2 bvh = build_flat(s, BuilderKind::kBinned);
  const double cost0 = bvh2_sah_cost(bvh);
  // Mesh 0 moves 100 units away and is squashed; mesh 1 is scrambled (every
  // vertex sent to a random place in a box 10x larger): the tree degrades.
  for (Vec3f& p : s.meshes[0].positions) p = Vec3f{p.x * 3.0f + 100.0f, p.y * 0.01f, p.z};
  test::Rng rng(11);
  for (Vec3f& p : s.meshes[1].positions)
    p = Vec3f{rng.uniform(), rng.uniform(), rng.uniform()} * 10.0f;
  const RefitResult r = run_with_threads(kThreads, [&] { return refit(bvh, s); });
  EXPECT_TRUE(r.valid);
  EXPECT_EQ(check_flat(bvh, s), "");
  EXPECT_GT(r.sah_cost, 2.0 * cost0);  // scrambled soup boxes span its whole range
}

TEST(Refit, DeterministicForAnyThreadCount) {
  Scene s = soup_scene();
  const Bvh2 built = build_flat(s, BuilderKind::kParallel);
  test::Rng rng(3);
  for (Vec3f& p : s.meshes[0].positions) p = p * 2.0f + Vec3f{rng.uniform(), 0.0f, 0.0f};
  Bvh2 one = built, two = built;
  const RefitResult r1 = run_with_threads(1, [&] { return refit(one, s); });
  const RefitResult r2 = run_with_threads(kThreads, [&] { return refit(two, s); });
  EXPECT_EQ(r1.sah_cost, r2.sah_cost);  // bit-identical
  for (size_t i = 0; i < one.nodes.size(); ++i) {
    ASSERT_EQ(one.nodes[i].min, two.nodes[i].min);
    ASSERT_EQ(one.nodes[i].max, two.nodes[i].max);
  }
}

TEST(Refit, ReportsATriangleThatBecameInvalid) {
  for (int how = 0; how < 3; ++how) {
    Scene s = soup_scene(2000);
    Bvh2 bvh = build_flat(s, BuilderKind::kBinned);
    TriangleMesh& m = s.meshes[0];
    const Vec3u t = m.triangles[1234];
    if (how == 0) m.positions[t[1]] = m.positions[t[0]];  // repeated vertex
    if (how == 1) m.positions[t[2]] = Vec3f{std::nanf(""), 0.0f, 0.0f};
    if (how == 2)
      m.positions[t[2]] = m.positions[t[0]] * 2.0f - m.positions[t[1]];  // collinear-ish
    const bool expect_valid = m.triangle_valid(1234);
    EXPECT_EQ(refit(bvh, s).valid, expect_valid) << how;
    if (how < 2) {
      EXPECT_FALSE(expect_valid);
    }
  }
}

// Nearly degenerate triangles whose normal is nonzero only below float
// precision (a component 2^-46, lost if a product is rounded first): prim
// info keeps them, and a refit that moves nothing must find them valid too
// (the two once computed the cross product with different FMA contractions
// and disagreed).
TEST(Refit, NearlyDegenerateTrianglesValidAsInPrimInfo) {
  const float e = std::ldexp(1.0f, -23);
  TriangleMesh m;
  test::add_triangle(m, {0, 0, 0}, {0, 1 + e, 1}, {0, 1 + 2 * e, 1 + e});
  test::add_triangle(m, {5, 0, 0}, {5, 1, 1 + e}, {5, 1 + e, 1 + 2 * e});
  test::add_triangle(m, {9, 0, 0}, {9, 1, 1}, {9, 2, 2});  // exactly collinear
  test::add_triangle(m, {0, 3, 0}, {1, 3, 0}, {0, 4, 0});
  EXPECT_TRUE(m.triangle_valid(0));
  EXPECT_TRUE(m.triangle_valid(1));
  EXPECT_FALSE(m.triangle_valid(2));
  Scene s;
  s.add_mesh(m);
  const PrimInfo prims = make_prim_info(s);
  EXPECT_EQ(prims.size(), 3u);
  const BuildTree tree = build_tree(prims, BuildOptions{});
  Bvh2 flat = flatten(tree, prims, s);
  WideBvh<8> wide = flatten_wide<8>(tree, prims, s);
  EXPECT_TRUE(refit(flat, s).valid);
  EXPECT_TRUE(refit(wide, s, RefitTriangles::kVerts, nullptr).valid);
}

// A 20k-triangle sphere under one deformer, fps 8.
Scene deforming_sphere(const char* kind, int frames) {
  Scene s;
  s.add_mesh(generate_sphere(20000));
  s.animation.frames = frames;
  s.animation.fps = 8.0f;
  DeformerSpec d;
  d.kind = kind;
  d.amplitude = std::string(kind) == "explode" ? 1.0f : 0.1f;
  d.angle_deg = 180.0f;
  s.animation.deformers = {d};
  return s;
}

TEST(Refit, EveryDeformerKeepsBoxesTight) {
  for (const char* kind : {"twist", "bend", "wave", "pulse", "explode"}) {
    Scene s = deforming_sphere(kind, 5);
    run_with_threads(kThreads, [&] {
      const SceneAnimator animator(s);  // unwelds for explode
      animator.apply(0, s);
      Bvh2 bvh = build_flat(s, BuilderKind::kParallel);
      for (int frame = 1; frame < animator.frames(); ++frame) {
        animator.apply(frame, s);
        const RefitResult r = refit(bvh, s);
        EXPECT_TRUE(r.valid) << kind << " frame " << frame;
        EXPECT_NEAR(r.sah_cost, bvh2_sah_cost(bvh), 1e-12 * r.sah_cost);
        ASSERT_EQ(check_flat(bvh, s), "") << kind << " frame " << frame;
      }
    });
  }
}

TEST(Refit, OnlyTheNamedTriangleArrayIsRewritten) {
  Scene s = soup_scene(5000);
  const Bvh2 built = build_flat(s, BuilderKind::kBinned);
  for (Vec3f& p : s.meshes[0].positions) p = p * 3.0f + Vec3f{1.0f, 2.0f, 3.0f};
  Bvh2 both = built, verts = built, edges = built;
  const RefitResult rb = refit(both, s, RefitTriangles::kBoth);
  const RefitResult rv = refit(verts, s, RefitTriangles::kVerts);
  const RefitResult re = refit(edges, s, RefitTriangles::kEdges);
  ASSERT_EQ(check_flat(both, s), "");
  EXPECT_EQ(rb.sah_cost, rv.sah_cost);
  EXPECT_EQ(rb.sah_cost, re.sah_cost);
  for (size_t i = 0; i < both.nodes.size(); ++i) {
    ASSERT_EQ(verts.nodes[i].min, both.nodes[i].min);
    ASSERT_EQ(edges.nodes[i].max, both.nodes[i].max);
  }
  for (size_t j = 0; j < 9 * both.triangles.size(); ++j) {
    ASSERT_EQ(verts.triangles.verts[j], both.triangles.verts[j]);
    ASSERT_EQ(edges.triangles.verts[j], built.triangles.verts[j]);  // untouched
  }
  for (size_t j = 0; j < both.triangles.size(); ++j) {
    ASSERT_EQ(verts.triangles.edges[j].e1, built.triangles.edges[j].e1);  // untouched
    ASSERT_EQ(edges.triangles.edges[j].e2, both.triangles.edges[j].e2);
  }
}

TEST(Refit, IndexGivesTheSameResult) {
  Scene s;
  s.add_mesh(generate_sphere(5000));
  s.add_mesh(test::random_soup(3000, 4));
  const Bvh2 built = build_flat(s, BuilderKind::kParallel);
  const RefitIndex index = make_refit_index(built, s);
  ASSERT_EQ(index.triangles.size(), built.triangles.size());
  for (Vec3f& p : s.meshes[0].positions) p = Vec3f{p.x * 2.0f, p.y + p.x, p.z};
  for (Vec3f& p : s.meshes[1].positions) p = p * 0.5f;
  Bvh2 with = built, without = built;
  const RefitResult a =
      run_with_threads(kThreads, [&] { return refit(with, s, RefitTriangles::kBoth, &index); });
  const RefitResult b = refit(without, s);
  EXPECT_EQ(a.sah_cost, b.sah_cost);
  EXPECT_EQ(check_flat(with, s), "");
  for (size_t i = 0; i < with.nodes.size(); ++i) {
    ASSERT_EQ(with.nodes[i].min, without.nodes[i].min);
    ASSERT_EQ(with.nodes[i].max, without.nodes[i].max);
  }
}

TEST(Refit, AllocatesNothing) {
  Scene s = soup_scene();
  Bvh2 bvh = build_flat(s, BuilderKind::kParallel);
  run_with_threads(kThreads, [&] {
    refit(bvh, s);  // warm-up: worker threads and TBB's task pools exist afterwards
    for (Vec3f& p : s.meshes[0].positions) p = p * 1.5f;
    const RefitIndex index = make_refit_index(bvh, s);
    g_allocations = 0;
    g_counting = true;
    const RefitResult r = refit(bvh, s, RefitTriangles::kBoth, &index);
    g_counting = false;
    EXPECT_TRUE(r.valid);
  });
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_EQ(check_flat(bvh, s), "");
}

// The wide layouts: the binary and a wide layout of one build, refitted over
// the same deformation, report the same SAH cost (the wide one sums the
// collapsed binary nodes' boxes), every wide slot stays exactly its contents,
// the result is the same on 1 and 2 threads, an invalid triangle is
// reported, and nothing is allocated.
template <int N>
void check_wide_refit() {
  for (const char* kind : {"twist", "explode"}) {
    SCOPED_TRACE(kind);
    Scene s = deforming_sphere(kind, 4);
    s.add_mesh(test::random_soup(3000, 9));
    const SceneAnimator animator(s);
    animator.apply(0, s);
    BuildOptions o;
    const PrimInfo prims = make_prim_info(s);
    const BuildTree tree = build_tree(prims, o);
    Bvh2 flat = flatten(tree, prims, s);
    const WideBvh<N> built = flatten_wide<N>(tree, prims, s);
    WideBvh<N> wide = built;
    for (int frame = 1; frame < animator.frames(); ++frame) {
      animator.apply(frame, s);
      const RefitResult rf = refit(flat, s);
      const RefitResult rw = run_with_threads(kThreads, [&] { return refit(wide, s); });
      EXPECT_TRUE(rw.valid);
      EXPECT_NEAR(rw.sah_cost, rf.sah_cost, 1e-12 * rf.sah_cost) << frame;
      EXPECT_NEAR(wide_sah_cost(wide), rw.sah_cost, 1e-12 * rw.sah_cost) << frame;
      ASSERT_EQ(test::check_wide(wide, s), "") << frame;
    }
    WideBvh<N> one = built;
    const RefitResult r1 = run_with_threads(1, [&] { return refit(one, s); });
    EXPECT_EQ(r1.sah_cost, wide_sah_cost(wide));
    for (size_t i = 0; i < one.nodes.size(); ++i)
      for (int row = 0; row < 6; ++row)
        for (int c = 0; c < N; ++c)
          ASSERT_EQ(one.nodes[i].bounds[row][c], wide.nodes[i].bounds[row][c]);
  }
  // An invalidated triangle, and no allocation on a refit with an index.
  Scene s = soup_scene(5000);
  const PrimInfo prims = make_prim_info(s);
  WideBvh<N> wide = flatten_wide<N>(build_tree(prims, BuildOptions{}), prims, s);
  run_with_threads(kThreads, [&] {
    refit(wide, s);
    const RefitIndex index = make_refit_index(wide.triangles, s);
    for (Vec3f& p : s.meshes[0].positions) p = p * 1.5f;
    g_allocations = 0;
    g_counting = true;
    const RefitResult r = refit(wide, s, RefitTriangles::kVerts, &index);
    g_counting = false;
    EXPECT_TRUE(r.valid);
  });
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_EQ(test::check_wide(wide, s), "");
  const Vec3u t = s.meshes[0].triangles[321];
  s.meshes[0].positions[t[1]] = s.meshes[0].positions[t[0]];
  EXPECT_FALSE(refit(wide, s).valid);
}

TEST(Refit, WideBvh4MatchesBinaryAndStaysExact) { check_wide_refit<4>(); }
TEST(Refit, WideBvh8MatchesBinaryAndStaysExact) { check_wide_refit<8>(); }

}  // namespace
}  // namespace hprt
