// The count and all queries (Intersector::count, intersect_all) on every
// layout: exact crossing counts on closed meshes for rays exactly through
// vertices and shared edges, lists in order of t with the truncation flag,
// and Embree's filter-callback answers beside them on generic rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "backends/intersector.h"
#include "core/error.h"
#include "core/parallel.h"
#include "tests/support/bvh_trace_helpers.h"
#include "tests/support/probe_rays.h"

namespace hprt {
namespace {

using test::aimed_at_vertices_and_edges;

std::unique_ptr<Intersector> built(const Scene& scene, BvhLayout layout,
                                   const std::string& backend = "bvh") {
  BackendOptions o;
  o.backend = backend;
  o.layout = layout;
  o.threads = 2;
  o.embree_robust = true;
  auto b = make_intersector(backend, o);
  b->build(scene);
  return b;
}

constexpr BvhLayout kLayouts[] = {BvhLayout::kBvh2, BvhLayout::kBvh4, BvhLayout::kBvh8};

// A convex closed mesh (an icosphere): from the centre through any vertex or
// edge exactly one crossing; from outside through one, on towards the
// centre and out: exactly two. Both queries, every layout.
TEST(Queries, CountsEachCrossingOnceThroughVerticesAndEdges) {
  Scene scene;
  scene.add_mesh(test::icosphere(3));
  const TriangleMesh& m = scene.meshes[0];
  const auto inside = aimed_at_vertices_and_edges(m, [](Vec3f) { return Vec3f{0, 0, 0}; });
  const auto outside = aimed_at_vertices_and_edges(m, [](Vec3f t) {
    return t * 3.0f + Vec3f{0.0f, 0.0f, 0.0f};
  });
  for (BvhLayout layout : kLayouts) {
    SCOPED_TRACE(to_string(layout));
    run_with_threads(2, [&] {
      auto b = built(scene, layout);
      for (const auto* set : {&inside, &outside}) {
        const uint32_t expected = set == &inside ? 1 : 2;
        std::vector<uint32_t> counts(set->size());
        b->count(*set, counts);
        HitLists lists;
        b->intersect_all(*set, 16, lists);
        ASSERT_EQ(lists.rays(), set->size());
        size_t wrong = 0;
        for (size_t i = 0; i < set->size(); ++i) {
          wrong += counts[i] != expected;
          EXPECT_EQ(lists.count(i), counts[i]) << i;
          EXPECT_EQ(lists.truncated[i], 0) << i;
          for (size_t k = 1; k < lists.count(i); ++k)
            EXPECT_TRUE(hit_list_before(lists.begin(i)[k - 1], lists.begin(i)[k])) << i;
        }
        EXPECT_EQ(wrong, 0u) << (expected == 1 ? "from inside" : "from outside");
      }
    });
  }
}

// The nearest hits are kept and the flag says the bound cut the list; the
// list equals the closest hit first.
TEST(Queries, AllKeepsTheNearestAndFlagsTruncation) {
  Scene scene;
  scene.add_mesh(test::icosphere(2));
  const auto rays = aimed_at_vertices_and_edges(scene.meshes[0], [](Vec3f t) { return t * 3.0f; });
  run_with_threads(2, [&] {
    auto b = built(scene, BvhLayout::kBvh8);
    HitLists one, two;
    b->intersect_all(rays, 1, one);
    b->intersect_all(rays, 2, two);
    std::vector<Hit> closest(rays.size());
    b->intersect(rays, closest);
    for (size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(one.count(i), 1u) << i;
      EXPECT_EQ(one.truncated[i], 1) << i;
      EXPECT_EQ(two.truncated[i], 0) << i;
      EXPECT_EQ(one.begin(i)[0].t, two.begin(i)[0].t) << i;
      EXPECT_EQ(one.begin(i)[0].t, closest[i].t) << i;
      EXPECT_LT(two.begin(i)[0].t, two.begin(i)[1].t) << i;
    }
  });
}

// Rays in (tnear, tfar] only; invalid rays have no hits.
TEST(Queries, IntervalAndInvalidRays) {
  Scene scene;
  scene.add_mesh(test::icosphere(2));
  Ray r;
  r.org = {0.01f, 0.02f, -5.0f};
  r.dir = {0, 0, 1};
  std::vector<Ray> rays(4, r);
  rays[1].tfar = 5.0f;      // only the near crossing (t ~ 4)
  rays[2].tnear = 5.0f;     // only the far one (t ~ 6)
  rays[3].dir = {0, 0, 0};  // invalid
  for (BvhLayout layout : kLayouts)
    for (const char* name : {"bvh", "embree"}) {
      SCOPED_TRACE(name);
      auto b = built(scene, layout, name);
      std::vector<uint32_t> counts(rays.size());
      b->count(rays, counts);
      EXPECT_EQ(counts, (std::vector<uint32_t>{2, 1, 1, 0}));
    }
}

// Embree's answers (a context filter collecting every hit) on generic random
// rays through a soup and a sphere: the same crossings.
TEST(Queries, EmbreeAgreesOnGenericRays) {
  for (const TriangleMesh& mesh : {test::random_soup(3000, 5, 0.05f), test::icosphere(4)}) {
    Scene scene;
    scene.add_mesh(mesh);
    const auto rays = test::random_rays(scene.bounds(), 3000, 11);
    run_with_threads(2, [&] {
      auto bvh = built(scene, BvhLayout::kBvh8);
      auto embree = built(scene, BvhLayout::kBvh8, "embree");
      std::vector<uint32_t> cb(rays.size()), ce(rays.size());
      bvh->count(rays, cb);
      embree->count(rays, ce);
      HitLists lb, le;
      bvh->intersect_all(rays, 64, lb);
      embree->intersect_all(rays, 64, le);
      size_t differ = 0, total = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        differ += cb[i] != ce[i];
        total += cb[i];
        ASSERT_EQ(le.count(i), ce[i]);
        if (cb[i] != ce[i]) continue;
        for (size_t k = 0; k < cb[i]; ++k) {
          EXPECT_EQ(lb.begin(i)[k].prim_id, le.begin(i)[k].prim_id) << i;
          EXPECT_NEAR(lb.begin(i)[k].t, le.begin(i)[k].t, 1e-4f * (1.0f + lb.begin(i)[k].t));
        }
      }
      EXPECT_GT(total, rays.size() / 20);  // enough crossings to compare
      EXPECT_EQ(differ, 0u);
    });
  }
}

TEST(Queries, PluginsCannotAnswer) {
  // The base class's answer, as for any backend without the queries.
  struct NoQueries final : Intersector {
    void build(const Scene&) override {}
    void update(const Scene&) override {}
    void intersect(std::span<const Ray>, std::span<Hit>) const override {}
    void occluded(const RayInput&, std::span<uint8_t>) const override {}
    BuildInfo info() const override { return {}; }
  } b;
  std::vector<Ray> rays(1);
  std::vector<uint32_t> counts(1);
  HitLists lists;
  EXPECT_THROW(b.count(rays, counts), OptionError);
  EXPECT_THROW(b.intersect_all(rays, 4, lists), OptionError);
}

}  // namespace
}  // namespace hprt
