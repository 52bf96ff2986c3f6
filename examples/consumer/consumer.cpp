// Loads a mesh (or makes one), traces rays through hprt's BVH and Embree
// with hprt's public API, and prints their diff as `hprt validate rays` does.
// Usage: hprt_consumer [MESH.obj|.ply] [RAY KIND] [COUNT]
#include <hprt/hprt.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace api = hprt::api;

// A 64 x 64 height field of 8,192 triangles, used when no mesh is named.
api::Scene wavy_sheet() {
  std::vector<float> v;
  std::vector<uint32_t> idx;
  const uint32_t n = 64;
  for (uint32_t j = 0; j <= n; ++j)
    for (uint32_t i = 0; i <= n; ++i) {
      const float x = float(i) / n - 0.5f, y = float(j) / n - 0.5f;
      v.insert(v.end(), {x, y, 0.05f * float(i % 7) * float(j % 5) / 24.0f});
    }
  for (uint32_t j = 0; j < n; ++j)
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i;
      idx.insert(idx.end(), {a, a + 1, a + n + 2, a, a + n + 2, a + n + 1});
    }
  api::Scene s;
  s.add_mesh(v, idx);
  return s;
}

int main(int argc, char** argv) {
  try {
    const api::Scene scene = argc > 1 ? api::Scene::from_file(argv[1]) : wavy_sheet();
    const std::string kind = argc > 2 ? argv[2] : "random";
    const size_t count = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 100000;
    const std::vector<api::Ray> rays = api::make_rays(scene, kind, count);

    api::Backend bvh("bvh"), embree("embree");
    bvh.build(scene);
    embree.build(scene);
    std::vector<api::Hit> hits(rays.size());
    bvh.intersect(rays, hits);
    size_t hit_count = 0;
    for (const api::Hit& h : hits) hit_count += h.prim_id != api::kInvalidId;
    std::printf(
        "hprt %s: %zu triangles, %zu %s rays, %zu hits; bvh build %.1f ms, embree %.1f ms\n",
        api::version(), scene.triangle_count(), rays.size(), kind.c_str(), hit_count,
        bvh.info().build_ms, embree.info().build_ms);

    const api::DiffReport d = api::diff(scene, bvh, embree, rays);
    std::fputs(d.summary.c_str(), stdout);
    return d.backend_wrong() == 0 ? 0 : 1;
  } catch (const api::Error& e) {
    std::fprintf(stderr, "hprt_consumer: error: %s\n", e.what());
    return 2;
  }
}
