// The plugin backend (backends/plugin_backend.h) with the test plugins of
// tests/plugins: a correct one answers as Embree does and bit for bit the
// same at 1 and 2 threads; every kind of broken plugin is refused with
// InputError naming the file and the problem; malformed answers are counted
// and turned into marked misses; options reach create().
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "backends/backend_spec.h"
#include "backends/intersector.h"
#include "core/error.h"
#include "core/hit_check.h"
#include "core/parallel.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {
namespace {

std::string plugin(const char* path, const std::string& options = "") {
  return std::string("plugin:") + path + (options.empty() ? "" : ":" + options);
}

Scene sphere_and_soup() {
  Scene s;
  s.add_mesh(generate_sphere(800));
  TriangleMesh soup = generate_soup(300, 7);
  s.add_mesh(std::move(soup));
  return s;
}

// The InputError text make_intersector (and build) throws for `spec`.
std::string load_error(const std::string& spec, bool build = false) {
  try {
    const Scene s = sphere_and_soup();
    auto p = make_intersector(spec, BackendOptions{});
    if (build) p->build(s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(BackendSpec, ParsesTheThreeForms) {
  EXPECT_EQ(parse_backend_spec("bvh").kind, BackendSpec::Kind::kBvh);
  EXPECT_EQ(parse_backend_spec("embree").kind, BackendSpec::Kind::kEmbree);
  const BackendSpec p = parse_backend_spec("plugin:./a/b.so:leaf=4,x=y:z");
  EXPECT_EQ(p.kind, BackendSpec::Kind::kPlugin);
  EXPECT_EQ(p.plugin_path, "./a/b.so");
  EXPECT_EQ(p.plugin_options, "leaf=4,x=y:z");
  EXPECT_EQ(parse_backend_spec("plugin:x.so").plugin_options, "");
  EXPECT_THROW(parse_backend_spec("plugin:"), OptionError);
  EXPECT_THROW(parse_backend_spec("plugin::opts"), OptionError);
  EXPECT_THROW(parse_backend_spec("optix"), OptionError);
  EXPECT_EQ(backend_spec_problem("bvh"), "");
  EXPECT_NE(backend_spec_problem("Embree"), "");
}

TEST(PluginBackend, CorrectPluginAnswersAsEmbree) {
  const Scene s = sphere_and_soup();
  const std::vector<Ray> rays = test::random_rays(s.bounds(), 4000, 3);
  for (int threads : {1, 2}) {
    run_with_threads(threads, [&] {
      auto p = make_intersector(plugin(HPRT_TEST_PLUGIN_GOOD), BackendOptions{});
      auto e = make_intersector("embree", BackendOptions{});
      p->build(s);
      e->build(s);
      std::vector<Hit> hp(rays.size()), he(rays.size());
      std::vector<uint8_t> op(rays.size()), oe(rays.size());
      p->intersect(rays, hp);
      e->intersect(rays, he);
      p->occluded(rays, op);
      e->occluded(rays, oe);
      size_t hits = 0, differ = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        hits += hp[i].hit();
        EXPECT_TRUE(hit_well_formed(s, rays[i], hp[i]));
        if (hp[i].hit() != he[i].hit() ||
            (hp[i].hit() && std::fabs(hp[i].t - he[i].t) > 1e-5f * he[i].t))
          ++differ;
        EXPECT_EQ(op[i], uint8_t(hp[i].hit())) << i;
      }
      EXPECT_GT(hits, rays.size() / 10);
      EXPECT_LE(differ, 2u);  // edge rays may split either way
      EXPECT_EQ(p->info().name, "plugin/test");
      EXPECT_EQ(p->info().malformed_answers, 0u);
    });
  }
}

TEST(PluginBackend, UpdateWithAndWithoutThePluginsUpdate) {
  Scene s = sphere_and_soup();
  const std::vector<Ray> rays = test::random_rays(s.bounds(), 500, 5);
  for (const char* path : {HPRT_TEST_PLUGIN_GOOD, HPRT_TEST_PLUGIN_OPTIONS_ECHO}) {
    auto p = make_intersector(plugin(path), BackendOptions{});
    p->build(s);
    for (Vec3f& v : s.meshes[0].positions) v = v * 0.5f;  // shrink the sphere
    p->update(s);
    // GOOD has update(); OPTIONS_ECHO has none and is built again.
    EXPECT_EQ(p->info().rebuilt, path == std::string(HPRT_TEST_PLUGIN_OPTIONS_ECHO));
    auto e = make_intersector("embree", BackendOptions{});
    e->build(s);
    std::vector<Hit> hp(rays.size()), he(rays.size());
    p->intersect(rays, hp);
    e->intersect(rays, he);
    size_t differ = 0;
    for (size_t i = 0; i < rays.size(); ++i) differ += hp[i].hit() != he[i].hit();
    EXPECT_LE(differ, 1u);
    for (Vec3f& v : s.meshes[0].positions) v = v * 2.0f;
  }
}

TEST(PluginBackend, UpdateRebuildBuildsAndAKeptPointerSeesTheNewFrame) {
  Scene s = sphere_and_soup();
  const std::vector<Ray> rays = test::random_rays(s.bounds(), 500, 5);
  // --update rebuild: build() every frame, even where the plugin has update().
  BackendOptions rebuild;
  rebuild.update = UpdateStrategy::kRebuild;
  auto good = make_intersector(plugin(HPRT_TEST_PLUGIN_GOOD), rebuild);
  good->build(s);
  good->update(s);
  EXPECT_TRUE(good->info().rebuilt);
  // KEEP's update() keeps the build's pointers: with the vertices moved in
  // place (as the CLI's animations and the Python module move them) it
  // answers for the new frame as Embree does. The Python suite checks that
  // update_triangles really writes into those arrays.
  auto keep = make_intersector(plugin(HPRT_TEST_PLUGIN_KEEP), BackendOptions{});
  keep->build(s);
  for (Vec3f& v : s.meshes[0].positions) v = v * 0.5f;
  keep->update(s);
  EXPECT_FALSE(keep->info().rebuilt);
  auto e = make_intersector("embree", BackendOptions{});
  e->build(s);
  std::vector<Hit> hk(rays.size()), he(rays.size());
  keep->intersect(rays, hk);
  e->intersect(rays, he);
  size_t differ = 0, hits = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    differ += hk[i].hit() != he[i].hit();
    hits += he[i].hit();
  }
  EXPECT_GT(hits, 10u);
  EXPECT_LE(differ, 1u);
}

TEST(PluginBackend, UnwrittenAnswersAreMalformedAndNamesPrintable) {
  const Scene s = sphere_and_soup();
  const std::vector<Ray> rays = test::random_rays(s.bounds(), 700, 3);
  auto p = make_intersector(plugin(HPRT_TEST_PLUGIN_SILENT), BackendOptions{});
  EXPECT_EQ(p->info().name, "plugin/si\\nlent\\x1b[0m");  // control characters escaped
  p->build(s);
  std::vector<Hit> h(rays.size(), Hit{});  // misses: hprt must not trust what was there
  p->intersect(rays, h);
  for (const Hit& x : h) EXPECT_TRUE(x.malformed() && !x.hit());
  EXPECT_EQ(p->info().malformed_answers, rays.size());
  std::vector<uint8_t> occ(rays.size(), 0);
  p->occluded(rays, occ);
  for (uint8_t o : occ) EXPECT_FALSE(occlusion_well_formed(o));
  EXPECT_EQ(p->info().malformed_answers, 2 * rays.size());
  EXPECT_NE(malformed_warning(p->info().name, 3).find("gave 3 malformed answers"),
            std::string::npos);
  EXPECT_EQ(malformed_warning(p->info().name, 0), "");
}

TEST(PluginBackend, BrokenPluginsAreRefusedNamingFileAndProblem) {
  struct Case {
    std::string spec;
    bool build;
    std::string problem;
  };
  const Case cases[] = {
      {plugin("/nonexistent/libnothing.so"), false, "plugin file not found"},
      {plugin(HPRT_SOURCE_DIR "/README.md"), false, "cannot load plugin"},
      {plugin(HPRT_TEST_PLUGIN_NO_ENTRY), false, "no hprt_plugin_entry symbol"},
      {plugin(HPRT_TEST_PLUGIN_ENTRY_NULL), false, "hprt_plugin_entry() returned NULL"},
      {plugin(HPRT_TEST_PLUGIN_BAD_ABI), false, "plugin ABI version 2, this hprt loads version 1"},
      {plugin(HPRT_TEST_PLUGIN_NULL_INTERSECT), false, "NULL 'intersect'"},
      {plugin(HPRT_TEST_PLUGIN_CREATE_FAILS), false,
       "create failed: this plugin always fails to create"},
      {plugin(HPRT_TEST_PLUGIN_GOOD, "fast=1"), false, "create failed: unknown option"},
      {plugin(HPRT_TEST_PLUGIN_OPTIONS_ECHO, "leaf=99"), false, "create failed"},
      {plugin(HPRT_TEST_PLUGIN_BUILD_FAILS), true, "build failed: mesh rejected by test plugin"},
  };
  for (const Case& c : cases) {
    const std::string msg = load_error(c.spec, c.build);
    const std::string path = parse_backend_spec(c.spec).plugin_path;
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << c.spec << " -> " << msg;
    EXPECT_NE(msg.find(c.problem), std::string::npos) << c.spec << " -> " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_EQ(load_error(plugin(HPRT_TEST_PLUGIN_OPTIONS_ECHO, "leaf=4"), true), "no error");
}

TEST(PluginBackend, MalformedAnswersAreCountedAndMarked) {
  const Scene s = sphere_and_soup();
  const std::vector<Ray> rays = test::random_rays(s.bounds(), 2000, 9);
  auto p = make_intersector(plugin(HPRT_TEST_PLUGIN_MALFORMED), BackendOptions{});
  auto good = make_intersector(plugin(HPRT_TEST_PLUGIN_GOOD), BackendOptions{});
  p->build(s);
  good->build(s);
  std::vector<Hit> hp(rays.size()), hg(rays.size());
  p->intersect(rays, hp);
  good->intersect(rays, hg);
  size_t marked = 0, expected = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    // The plugin corrupts hits at batch index % 4 != 3 (batches start at multiples of 256).
    const bool corrupted = hg[i].hit() && i % 4 != 3;
    expected += corrupted;
    marked += hp[i].malformed();
    EXPECT_EQ(hp[i].malformed(), corrupted) << i;
    EXPECT_FALSE(hp[i].hit() && !hit_well_formed(s, rays[i], hp[i]));
  }
  EXPECT_GT(expected, 100u);
  EXPECT_EQ(marked, expected);
  EXPECT_EQ(p->info().malformed_answers, expected);
  std::vector<uint8_t> occ(rays.size());
  p->occluded(rays, occ);
  EXPECT_GT(p->info().malformed_answers, expected);  // bytes of 2
}

}  // namespace
}  // namespace hprt
