// The public C++ API (include/hprt/hprt.h) through libhprt.so alone, as a
// consumer sees it: scenes from arrays and files, backends by name with the
// command line's options, queries, update, diff and render, and errors as
// hprt::api::Error with the CLI's one-line message.
#include <gtest/gtest.h>
#include <hprt/hprt.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace api = hprt::api;

// An n x n grid of quads (2 triangles each) in the plane z = 0, [-1, 1]^2.
struct Grid {
  std::vector<float> vertices;
  std::vector<uint32_t> indices;
};
Grid grid(uint32_t n) {
  Grid g;
  for (uint32_t j = 0; j <= n; ++j)
    for (uint32_t i = 0; i <= n; ++i)
      g.vertices.insert(g.vertices.end(), {-1.0f + 2.0f * float(i) / float(n),
                                           -1.0f + 2.0f * float(j) / float(n), 0.0f});
  for (uint32_t j = 0; j < n; ++j)
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      g.indices.insert(g.indices.end(), {a, b, d, a, d, c});
    }
  return g;
}

api::Ray down(float x, float y, float z = 2.0f) {
  return {x, y, z, 0.0f, 0.0f, 0.0f, -1.0f, std::numeric_limits<float>::infinity()};
}

std::string error_of(const auto& f) {
  try {
    f();
  } catch (const api::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(Api, SceneFromArraysAnswersOnEveryBackend) {
  api::Scene scene;
  const Grid g = grid(8);
  EXPECT_EQ(scene.add_mesh(g.vertices, g.indices), 0u);
  EXPECT_EQ(scene.triangle_count(), 128u);
  EXPECT_EQ(scene.vertex_count(0), 81u);
  EXPECT_EQ(scene.bounds()[0], -1.0f);
  EXPECT_EQ(scene.bounds()[5], 0.0f);
  const std::vector<api::Ray> rays = {down(0.1f, 0.2f), down(3.0f, 0.0f), down(-0.93f, 0.61f)};
  for (const char* name : {"bvh", "embree"}) {
    api::Backend b(name, {{"threads", "2"}});
    b.build(scene);
    std::vector<api::Hit> hits(rays.size());
    std::vector<uint8_t> occ(rays.size());
    b.intersect(rays, hits);
    b.occluded(rays, occ);
    EXPECT_FLOAT_EQ(hits[0].t, 2.0f) << name;
    EXPECT_EQ(hits[0].geom_id, 0u);
    EXPECT_LT(hits[0].prim_id, 128u);
    EXPECT_TRUE(std::isinf(hits[1].t));
    EXPECT_EQ(hits[1].prim_id, api::kInvalidId);
    EXPECT_EQ(hits[2].geom_id, 0u);
    EXPECT_EQ(occ, (std::vector<uint8_t>{1, 0, 1}));
    EXPECT_FALSE(b.info().name.empty());
  }
}

TEST(Api, OptionsUseTheCommandLinesNamesAndChecks) {
  api::Scene scene;
  const Grid g = grid(4);
  scene.add_mesh(g.vertices, g.indices);
  api::Backend b("bvh", {{"builder", "morton"}, {"layout", "bvh4"}, {"leaf_size", "2"}});
  b.build(scene);
  EXPECT_EQ(b.info().name, "bvh/morton/watertight/bvh4");
  EXPECT_GT(b.info().memory_bytes, 0u);
  EXPECT_EQ(error_of([] {
              api::Backend("bvh", {{"leaf_size", "0"}});
            }),
            "leaf_size: must be in [1, 255], got 0");
  EXPECT_EQ(error_of([] {
              api::Backend("bvh", {{"sah_leaf_block", "0"}});
            }),
            "sah_leaf_block: must be in [1, 64], got 0");
  api::Backend blocks("bvh", {{"sah_leaf_block", "4"}, {"leaf_size", "16"}});
  blocks.build(scene);
  EXPECT_GT(blocks.info().memory_bytes, 0u);
  EXPECT_EQ(error_of([] {
              api::Backend("bvh", {{"builder", "fast"}});
            }),
            "builder: expected sweep, presorted, binned, parallel or morton, got 'fast'");
  EXPECT_NE(error_of([] {
              api::Backend("bvh", {{"colour", "red"}});
            }).find("colour: unknown"),
            std::string::npos);
  EXPECT_NE(error_of([] { api::Backend("optix"); }).find("unknown backend 'optix'"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              api::Backend("plugin:/no/such.so");
            }).find("/no/such.so: plugin file not found"),
            std::string::npos);
  EXPECT_NE(error_of([] { api::Scene::from_file("/no/such/mesh.obj"); }).find("/no/such/mesh.obj"),
            std::string::npos);
}

TEST(Api, UpdateSeesMovedVertices) {
  api::Scene scene;
  Grid g = grid(4);
  scene.add_mesh(g.vertices, g.indices);
  for (const char* update : {"refit", "rebuild"}) {
    api::Backend b("bvh", {{"update", update}});
    b.build(scene);
    for (size_t i = 2; i < g.vertices.size(); i += 3) g.vertices[i] = 0.5f;
    scene.set_vertices(0, g.vertices);
    b.update(scene);
    std::vector<api::Ray> rays = {down(0.0f, 0.0f)};
    std::vector<api::Hit> hits(1);
    b.intersect(rays, hits);
    EXPECT_FLOAT_EQ(hits[0].t, 1.5f) << update;
    for (size_t i = 2; i < g.vertices.size(); i += 3) g.vertices[i] = 0.0f;
    scene.set_vertices(0, g.vertices);
  }
  EXPECT_THROW(scene.set_vertices(0, std::vector<float>(3)), std::invalid_argument);
  const std::vector<uint32_t> bad = {0, 1, 99};
  EXPECT_EQ(error_of([&] { scene.add_mesh(g.vertices, bad); }),
            "add_mesh: triangle 0 references vertex 99 of 25");
}

TEST(Api, DiffOfTwoBackendsAndAPluginThatLies) {
  api::Scene scene;
  const Grid g = grid(16);
  scene.add_mesh(g.vertices, g.indices);
  const std::vector<api::Ray> rays = api::make_rays(scene, "primary", 3000, 4);
  ASSERT_EQ(rays.size(), 3000u);
  api::Backend bvh("bvh"), embree("embree"), good(std::string("plugin:") + HPRT_TEST_PLUGIN_GOOD),
      bad(std::string("plugin:") + HPRT_TEST_PLUGIN_MALFORMED);
  for (api::Backend* b : {&bvh, &embree, &good, &bad}) b->build(scene);
  const api::DiffReport d = api::diff(scene, bvh, embree, rays);
  EXPECT_EQ(d.rays, 3000u);
  EXPECT_EQ(d.backend_wrong(), 0u);
  EXPECT_EQ(d.verdicts.size(), 3000u);
  EXPECT_EQ(d.agree + d.ties + d.mismatches, d.rays);
  EXPECT_NE(d.summary.find("wrong on 0 rays: pass"), std::string::npos) << d.summary;
  EXPECT_EQ(api::diff(scene, good, embree, rays).backend_wrong(), 0u);
  const api::DiffReport lies = api::diff(scene, bad, embree, rays);
  EXPECT_GT(lies.backend_malformed, 100u);
  EXPECT_GE(lies.backend_wrong(), lies.backend_malformed);
  EXPECT_NE(lies.summary.find("FAIL"), std::string::npos);
  EXPECT_THROW(api::make_rays(scene, "sideways", 10), api::Error);
}

// Scene::normals gives each triangle's unit normal; intersect into columns
// gives the records' answers and the hit triangle's normal, the same bits on
// every backend (a plugin's through the library's own pass; its malformed
// answers are misses), zero on a miss; any column may be left out; a short
// column throws; after update the moved triangles' normals.
TEST(Api, IntersectIntoColumnsOnEveryBackend) {
  api::Scene scene;
  Grid g = grid(16);
  for (size_t i = 0; i < g.vertices.size(); i += 3)  // a saddle: every normal differs
    g.vertices[i + 2] = 0.3f * g.vertices[i] * g.vertices[i + 1];
  scene.add_mesh(g.vertices, g.indices);
  std::vector<float> table(3 * scene.triangle_count());
  scene.normals(0, table);
  EXPECT_THROW(scene.normals(0, std::span<float>(table).first(table.size() - 1)),
               std::invalid_argument);
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    const float* n = &table[3 * t];
    EXPECT_NEAR(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2], 1.0, 1e-6);
    const uint32_t* idx = &g.indices[3 * t];
    const float* a = &g.vertices[3 * idx[0]];
    const float* b = &g.vertices[3 * idx[1]];
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    EXPECT_NEAR(n[0] * e1[0] + n[1] * e1[1] + n[2] * e1[2], 0.0, 1e-6);  // normal to an edge
    EXPECT_GT(n[2], 0.0f);  // counter-clockwise from +z
  }
  std::vector<api::Ray> rays = api::make_rays(scene, "random", 2000, 6);
  rays.push_back(down(5.0f, 5.0f));  // a miss
  api::Backend bvh("bvh"), embree("embree"), good(std::string("plugin:") + HPRT_TEST_PLUGIN_GOOD);
  const size_t n = rays.size();
  struct Columns {
    std::vector<float> t, uv, normal;
    std::vector<uint32_t> geom, prim;
    explicit Columns(size_t n)
        : t(n, 7.0f), uv(2 * n, 7.0f), normal(3 * n, 7.0f), geom(n, 7), prim(n, 7) {}
    api::HitColumns all() { return {t, geom, prim, uv, normal}; }
  };
  for (api::Backend* b : {&bvh, &embree, &good}) {
    b->build(scene);
    std::vector<api::Hit> plain(n);
    b->intersect(rays, plain);
    // `some`: two columns, each one entry longer than needed: the extra
    // entry stays untouched.
    Columns c(n), some(n + 1);
    b->intersect(rays, c.all());
    b->intersect(rays, api::HitColumns{{}, {}, some.prim, {}, some.normal});
    EXPECT_EQ(some.prim[n], 7u);
    EXPECT_TRUE(some.normal[3 * n] == 7.0f && some.normal[3 * n + 2] == 7.0f);
    size_t hit = 0;
    for (size_t i = 0; i < n; ++i) {
      const api::Hit column{c.t[i], c.uv[2 * i], c.uv[2 * i + 1], c.geom[i], c.prim[i]};
      ASSERT_EQ(std::memcmp(&column, &plain[i], sizeof(api::Hit)), 0) << b->info().name;
      ASSERT_EQ(some.prim[i], plain[i].prim_id);
      const float zero[3] = {0.0f, 0.0f, 0.0f};
      const float* want = plain[i].prim_id == api::kInvalidId ? zero : &table[3 * plain[i].prim_id];
      hit += want != zero;
      ASSERT_EQ(std::memcmp(&c.normal[3 * i], want, 3 * sizeof(float)), 0)
          << b->info().name << " ray " << i;
      ASSERT_EQ(std::memcmp(&some.normal[3 * i], want, 3 * sizeof(float)), 0);
    }
    EXPECT_GT(hit, n / 10) << b->info().name;
    // The same rays as six floats each (RayArray): the same columns, bit for bit.
    std::vector<float> six;
    for (const api::Ray& r : rays) {
      ASSERT_TRUE(r.tnear == rays[0].tnear && r.tfar == rays[0].tfar);
      six.insert(six.end(), {r.org_x, r.org_y, r.org_z, r.dir_x, r.dir_y, r.dir_z});
    }
    Columns from_six(n);
    b->intersect(api::RayArray{six, rays[0].tnear, rays[0].tfar}, from_six.all());
    EXPECT_EQ(std::memcmp(from_six.t.data(), c.t.data(), n * sizeof(float)), 0);
    EXPECT_EQ(from_six.prim, c.prim);
    EXPECT_EQ(from_six.geom, c.geom);
    EXPECT_EQ(std::memcmp(from_six.uv.data(), c.uv.data(), 2 * n * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(from_six.normal.data(), c.normal.data(), 3 * n * sizeof(float)), 0);
    EXPECT_THROW(b->intersect(api::RayArray{std::span<const float>(six).first(six.size() - 1)},
                              from_six.all()),
                 std::invalid_argument);
    // occluded from six floats: the records' answers with the same interval,
    // one that cuts some hits off too.
    size_t occluded_count[2] = {0, 0};
    const float interval[2][2] = {{0.0f, std::numeric_limits<float>::infinity()}, {0.2f, 1.0f}};
    for (int k = 0; k < 2; ++k) {
      std::vector<api::Ray> cut = rays;
      for (api::Ray& r : cut) r.tnear = interval[k][0], r.tfar = interval[k][1];
      std::vector<uint8_t> want(n), got(n, 7);
      b->occluded(cut, want);
      b->occluded(api::RayArray{six, interval[k][0], interval[k][1]}, got);
      EXPECT_EQ(got, want) << b->info().name;
      occluded_count[k] = size_t(std::count(want.begin(), want.end(), 1));
    }
    EXPECT_GT(occluded_count[0], occluded_count[1]) << b->info().name;
    EXPECT_GT(occluded_count[1], 0u) << b->info().name;
    std::vector<uint8_t> short_result(n - 1);
    EXPECT_THROW(b->occluded(api::RayArray{six}, short_result), std::invalid_argument);
    EXPECT_THROW(
        b->occluded(api::RayArray{std::span<const float>(six).first(six.size() - 1)}, short_result),
        std::invalid_argument);
    EXPECT_NO_THROW(b->occluded(api::RayArray{}, {}));  // no rays
    if (b != &good) {                                   // plugins cannot count (ABI v1)
      std::vector<uint32_t> count_records(n), count_six(n, 7);
      b->count(rays, count_records);
      b->count(api::RayArray{six, rays[0].tnear, rays[0].tfar}, count_six);
      EXPECT_EQ(count_records, count_six) << b->info().name;
      const api::Backend::HitLists all_records = b->intersect_all(rays, 3);
      const api::Backend::HitLists all_six =
          b->intersect_all(api::RayArray{six, rays[0].tnear, rays[0].tfar}, 3);
      EXPECT_EQ(all_records.offsets, all_six.offsets);
      EXPECT_EQ(all_records.truncated, all_six.truncated);
      ASSERT_EQ(all_records.hits.size(), all_six.hits.size());
      EXPECT_EQ(std::memcmp(all_records.hits.data(), all_six.hits.data(),
                            all_six.hits.size() * sizeof(api::Hit)),
                0);
    }
    EXPECT_NO_THROW(b->intersect(api::RayArray{}, api::HitColumns{}));
    for (int k = 0; k < 5; ++k) {  // each column one entry short
      Columns s(n);
      api::HitColumns cols = s.all();
      std::span<float>* floats[] = {&cols.t, &cols.uv, &cols.normal};
      std::span<uint32_t>* ids[] = {&cols.geom_id, &cols.prim_id};
      if (k < 3)
        *floats[k] = floats[k]->first(floats[k]->size() - 1);
      else
        *ids[k - 3] = ids[k - 3]->first(n - 1);
      EXPECT_THROW(b->intersect(rays, cols), std::invalid_argument) << k;
    }
  }
  // A plugin's malformed answers (t = NaN in a record) are misses in columns,
  // with t NaN there too.
  api::Backend bad(std::string("plugin:") + HPRT_TEST_PLUGIN_MALFORMED);
  bad.build(scene);
  std::vector<api::Hit> records(n);
  bad.intersect(rays, records);
  Columns c(n);
  bad.intersect(rays, c.all());
  size_t malformed = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isnan(records[i].t) || records[i].prim_id != api::kInvalidId) continue;
    ++malformed;
    EXPECT_TRUE(std::isnan(c.t[i]) && c.prim[i] == api::kInvalidId && c.geom[i] == api::kInvalidId);
    EXPECT_TRUE(c.normal[3 * i] == 0.0f && c.uv[2 * i] == 0.0f);
  }
  EXPECT_GT(malformed, 0u);
  // Moved vertices: after update the hits name the moved triangles' normals.
  for (size_t i = 0; i < g.vertices.size(); i += 3) g.vertices[i + 2] *= -1.0f;
  scene.set_vertices(0, g.vertices);
  scene.normals(0, table);
  for (api::Backend* b : {&bvh, &embree}) {
    b->update(scene);
    Columns moved(n);
    b->intersect(rays, moved.all());
    for (size_t i = 0; i < n; ++i) {
      if (moved.prim[i] == api::kInvalidId) continue;
      ASSERT_EQ(std::memcmp(&moved.normal[3 * i], &table[3 * moved.prim[i]], 3 * sizeof(float)), 0)
          << b->info().name << " ray " << i;
    }
  }
}

TEST(Api, SharedMeshesAreNotCopied) {
  Grid g = grid(8);
  api::Scene scene;
  const uint32_t id = scene.add_mesh_shared(g.vertices, g.indices);
  EXPECT_TRUE(scene.shared(id));
  EXPECT_EQ(scene.vertices(id).data(), g.vertices.data());
  EXPECT_EQ(scene.indices(id).data(), g.indices.data());
  const std::vector<api::Ray> rays = {down(0.3f, -0.2f)};
  std::vector<api::Hit> hits(1);
  for (const char* name : {"bvh", "embree"}) {
    api::Backend b(name);
    b.build(scene);
    EXPECT_EQ(scene.vertices(id).data(), g.vertices.data()) << name;  // still not copied
    b.intersect(rays, hits);
    EXPECT_FLOAT_EQ(hits[0].t, 2.0f);
    // Moved in place by the caller, then update().
    for (size_t i = 2; i < g.vertices.size(); i += 3) g.vertices[i] = -1.0f;
    b.update(scene);
    b.intersect(rays, hits);
    EXPECT_FLOAT_EQ(hits[0].t, 3.0f) << name;
    for (size_t i = 2; i < g.vertices.size(); i += 3) g.vertices[i] = 0.0f;
  }
  // set_vertices on a shared mesh shares the new array.
  std::vector<float> moved = g.vertices;
  scene.set_vertices(id, moved);
  EXPECT_EQ(scene.vertices(id).data(), moved.data());
  EXPECT_FALSE(scene.shared(scene.add_mesh(g.vertices, g.indices)));
}

TEST(Api, RenderFillsTheBuffer) {
  api::Scene scene;
  const Grid g = grid(4);
  scene.add_mesh(g.vertices, g.indices);
  api::Backend b;
  b.build(scene);
  const api::Image img = api::render(scene, b, 40, 0);
  EXPECT_EQ(img.width, 40);
  EXPECT_EQ(img.height, 30);  // the default camera's 4:3
  ASSERT_EQ(img.rgb.size(), size_t(3 * 40 * 30));
  // The centre sees the lit grid, brighter than the background corner.
  const size_t centre = 3 * (15 * 40 + 20);
  EXPECT_GT(img.rgb[centre], img.rgb[0]);
  EXPECT_STREQ(api::version(), "0.1.0");
}

// Released large blocks are handed out again (their pages already mapped),
// up to the memory's bound; a block in use is never handed out twice; small
// ones come from the heap and are never cached.
TEST(Api, ResultMemoryReusesReleasedLargeBlocks) {
  constexpr size_t kMiB = size_t{1} << 20;
  api::ResultMemory memory(16 * kMiB);
  auto* big = static_cast<float*>(memory.acquire(4 * kMiB));
  big[0] = 1.0f;
  big[kMiB - 1] = 2.0f;
  EXPECT_EQ(memory.cached_bytes(), 0u);
  memory.release(big);
  EXPECT_GE(memory.cached_bytes(), 4 * kMiB);
  EXPECT_EQ(memory.acquire(4 * kMiB), big);
  EXPECT_EQ(memory.cached_bytes(), 0u);
  void* other = memory.acquire(4 * kMiB);  // the cached one is in use: a fresh block
  EXPECT_NE(other, big);
  memory.release(other);
  memory.release(big);
  // Beyond the bound: freed, not cached.
  const size_t cached = memory.cached_bytes();
  memory.release(memory.acquire(32 * kMiB));
  EXPECT_EQ(memory.cached_bytes(), cached);
  // Small blocks: aligned, never cached (also for 0 bytes).
  for (const size_t bytes : {size_t{0}, size_t{1}, size_t{100}, size_t{64 * 1024}}) {
    void* p = memory.acquire(bytes);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(p) % 64, 0u);
    const size_t before = memory.cached_bytes();
    memory.release(p);
    EXPECT_EQ(memory.cached_bytes(), before);
  }
  memory.release(nullptr);
}

}  // namespace
