#include "workload/workload_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/camera.h"
#include "core/error.h"
#include "core/ray_offset.h"
#include "workload/sampling.h"
#include "workload/surface_hits.h"

namespace hprt {

std::vector<Ray> primary_rays(const Scene& scene, size_t n, SplitMix64& rng) {
  const CameraRays cam(scene.camera);
  const double pixels = double(cam.width()) * cam.height();
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    double p = std::floor((double(i) + rng.uniform()) * pixels / double(n));
    p = std::min(p, pixels - 1.0);
    const double y = std::floor(p / cam.width());
    const double x = p - y * cam.width();
    rays[i] = cam.ray(float(x) + rng.uniform(), float(y) + rng.uniform());
  }
  return rays;
}

std::vector<Ray> shadow_rays(const Scene& scene, size_t n, SplitMix64& rng,
                             const Intersector* backend) {
  if (scene.lights.empty()) throw OptionError("kind", "shadow rays need a light in the scene");
  const Light& light = scene.lights.front();
  const std::vector<SurfaceHit> hits = primary_surface_hits(scene, n, rng, backend, "shadow");
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    Ray& r = rays[i];
    r.org = offset_ray(hits[i].p, hits[i].n);
    r.tnear = 0.0f;
    if (light.type == LightType::kPoint) {
      // Unnormalised direction: the light sits at t = 1; stop just short of it.
      r.dir = light.position - r.org;
      r.tfar = 1.0f - 1e-4f;
    } else {
      r.dir = normalize(-light.direction);
      r.tfar = std::numeric_limits<float>::infinity();
    }
  }
  return rays;
}

std::vector<Ray> reflection_rays(const Scene& scene, size_t n, SplitMix64& rng,
                                 const Intersector* backend) {
  const std::vector<SurfaceHit> hits = primary_surface_hits(scene, n, rng, backend, "reflection");
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    const SurfaceHit& h = hits[i];
    const Vec3f d = normalize(h.dir);
    rays[i].org = offset_ray(h.p, h.n);
    rays[i].dir = d - h.n * (2.0f * dot(d, h.n));
  }
  return rays;
}

std::vector<Ray> diffuse_rays(const Scene& scene, size_t n, SplitMix64& rng,
                              const Intersector* backend) {
  const std::vector<SurfaceHit> hits = primary_surface_hits(scene, n, rng, backend, "diffuse");
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f& nrm = hits[i].n;
    rays[i].org = offset_ray(hits[i].p, nrm);
    rays[i].dir = cosine_hemisphere(nrm, rng);
  }
  return rays;
}

std::vector<Ray> random_rays(const Scene& scene, size_t n, SplitMix64& rng) {
  const AABB box = scene_box_or_unit(scene);
  const Vec3f c = box.center(), half = box.diagonal() * 0.55f;  // 10% larger box
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    r.org =
        c + Vec3f(half.x * (2.0f * rng.uniform() - 1.0f), half.y * (2.0f * rng.uniform() - 1.0f),
                  half.z * (2.0f * rng.uniform() - 1.0f));
    r.dir = uniform_sphere(rng);
  }
  return rays;
}

}  // namespace hprt
