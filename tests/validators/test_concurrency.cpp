// One built intersector answered from many std::threads at once: each thread
// calls intersect/occluded on its own batch (the backends use tbb::parallel_for
// inside) and every answer equals the single-threaded answer bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "backends/intersector.h"
#include "core/parallel.h"
#include "io/scene/scene_reader.h"
#include "meshgen/mesh_generators.h"
#include "tests/support/bvh_trace_helpers.h"
#include "validators/ray_sets.h"

namespace hprt {
namespace {

// ThreadSanitizer slows instrumented traversal ~50x and oversubscribed TBB
// workers spin: smaller batches there, still overlapping calls.
#if defined(__SANITIZE_THREAD__)
constexpr int kCallers = 4;
constexpr int kRepeats = 2;
constexpr size_t kRaysPerBatch = 200;
constexpr int kArenas = 2;
constexpr size_t kSphereTris = 1500, kSoupTris = 1000;
#else
constexpr int kCallers = 8;             // std::threads calling the one intersector together
constexpr int kRepeats = 3;             // calls per thread, so calls overlap
constexpr size_t kRaysPerBatch = 3000;  // per batch
constexpr int kArenas = 4;
constexpr size_t kSphereTris = 6000, kSoupTris = 4000;
#endif

Scene make_scene() {
  Scene s;
  s.add_mesh(generate_sphere(kSphereTris));
  s.add_mesh(generate_soup(kSoupTris, 11));
  s.camera = framing_camera(s.bounds(), s.camera);
  s.lights = {head_light(s.camera)};
  return s;
}

void check_concurrent_answers(const std::string& backend_name) {
  const Scene scene = make_scene();
  BackendOptions o;
  o.backend = backend_name;
  o.threads = 2;
  std::unique_ptr<Intersector> isect = make_intersector(backend_name, o);
  isect->build(scene);

  // Each caller has its own batch: a different ray kind or seed.
  const RayKind kinds[] = {RayKind::kPrimary, RayKind::kRandom, RayKind::kGrazing, RayKind::kNan};
  std::vector<std::vector<Ray>> batches(kCallers);
  for (int t = 0; t < kCallers; ++t)
    batches[t] = make_rays(scene, kinds[t % 4], kRaysPerBatch, 100 + t, isect.get());

  // Reference: one thread, one call per batch.
  std::vector<std::vector<Hit>> ref_hits(kCallers);
  std::vector<std::vector<uint8_t>> ref_occ(kCallers);
  size_t ref_hit_count = 0;
  for (int t = 0; t < kCallers; ++t) {
    ref_hits[t].resize(batches[t].size());
    ref_occ[t].resize(batches[t].size());
    isect->intersect(batches[t], ref_hits[t]);
    isect->occluded(batches[t], ref_occ[t]);
    for (const Hit& h : ref_hits[t]) ref_hit_count += h.hit() ? 1 : 0;
  }
  ASSERT_GT(ref_hit_count, size_t(kRaysPerBatch) / 2);  // the batches really hit something

  // Many std::threads on the same const intersector at once.
  std::vector<std::vector<Hit>> hits(kCallers * kRepeats);
  std::vector<std::vector<uint8_t>> occ(kCallers * kRepeats);
  std::vector<std::thread> callers;
  for (int t = 0; t < kCallers; ++t)
    callers.emplace_back([&, t] {
      const Intersector& shared = *isect;
      for (int r = 0; r < kRepeats; ++r) {
        const int slot = t * kRepeats + r;
        hits[slot].resize(batches[t].size());
        occ[slot].resize(batches[t].size());
        // Alternate the order so intersect and occluded calls overlap.
        if ((t + r) % 2) {
          shared.intersect(batches[t], hits[slot]);
          shared.occluded(batches[t], occ[slot]);
        } else {
          shared.occluded(batches[t], occ[slot]);
          shared.intersect(batches[t], hits[slot]);
        }
      }
    });
  for (std::thread& c : callers) c.join();

  for (int t = 0; t < kCallers; ++t)
    for (int r = 0; r < kRepeats; ++r) {
      const int slot = t * kRepeats + r;
      size_t bad_hits = 0, bad_occ = 0;
      for (size_t i = 0; i < batches[t].size(); ++i) {
        bad_hits += test::same_hit(hits[slot][i], ref_hits[t][i]) ? 0 : 1;
        bad_occ += occ[slot][i] == ref_occ[t][i] ? 0 : 1;
      }
      EXPECT_EQ(bad_hits, 0u) << backend_name << " caller " << t << " repeat " << r;
      EXPECT_EQ(bad_occ, 0u) << backend_name << " caller " << t << " repeat " << r;
    }
}

TEST(Concurrency, BvhAnswersManyThreadsLikeOne) { check_concurrent_answers("bvh"); }
TEST(Concurrency, EmbreeAnswersManyThreadsLikeOne) { check_concurrent_answers("embree"); }

// Callers inside their own task arenas (as `--threads` runs do) share it too.
TEST(Concurrency, BvhCallersInSeparateArenas) {
  const Scene scene = make_scene();
  BackendOptions o;
  o.threads = 2;
  std::unique_ptr<Intersector> isect = make_intersector("bvh", o);
  isect->build(scene);
  const std::vector<Ray> rays = make_rays(scene, RayKind::kRandom, kRaysPerBatch, 7);
  std::vector<Hit> ref(rays.size());
  isect->intersect(rays, ref);
  std::vector<std::vector<Hit>> got(kArenas, std::vector<Hit>(rays.size()));
  std::vector<std::thread> callers;
  for (int t = 0; t < kArenas; ++t)
    callers.emplace_back(
        [&, t] { run_with_threads(1 + t, [&] { isect->intersect(rays, got[t]); }); });
  for (std::thread& c : callers) c.join();
  for (int t = 0; t < kArenas; ++t) {
    size_t bad = 0;
    for (size_t i = 0; i < rays.size(); ++i) bad += test::same_hit(got[t][i], ref[i]) ? 0 : 1;
    EXPECT_EQ(bad, 0u) << "arena of " << 1 + t << " threads";
  }
}

}  // namespace
}  // namespace hprt
