// make_rays, diff and render of the public API: thin wrappers over
// validators/ray_sets.h, validators/ray_diff.h and render/whitted.h.
#include <tbb/task_arena.h>

#include <algorithm>
#include <memory>

#include "api/api_errors.h"
#include "api/api_scene.h"
#include "render/camera_override.h"
#include "render/framebuffer.h"
#include "render/whitted.h"
#include "validators/ray_diff.h"
#include "validators/ray_diff_summary.h"
#include "validators/ray_sets.h"

namespace hprt::api {

static_assert(kMaxRays == kMaxRaySetSize);
static_assert(uint8_t(Verdict::kBothWrong) == uint8_t(RayVerdict::kBothWrong) &&
              uint8_t(Verdict::kBackendRight) == uint8_t(RayVerdict::kBvhRight));

std::vector<Ray> make_rays(const Scene& scene, const std::string& kind, size_t count,
                           uint64_t seed) {
  return translate_errors([&] {
    const hprt::Scene& s = scene.impl().scene;
    const RayKind k = parse_ray_kind(kind);
    check_ray_count("count", count);
    // Surface points come from Embree, as `hprt rays` and `hprt validate rays` take them.
    std::unique_ptr<Intersector> embree;
    if (ray_kind_needs_backend(k)) {
      embree = make_intersector("embree", BackendOptions{});
      embree->build(s);
    }
    const std::vector<hprt::Ray> rays = hprt::make_rays(s, k, count, seed, embree.get());
    std::vector<Ray> out(rays.size());
    std::copy_n(reinterpret_cast<const Ray*>(rays.data()), rays.size(), out.data());
    return out;
  });
}

DiffReport diff(const Scene& scene, const Backend& backend, const Backend& reference,
                std::span<const Ray> rays, bool occluded) {
  return translate_errors([&] {
    const std::span<const hprt::Ray> r(reinterpret_cast<const hprt::Ray*>(rays.data()),
                                       rays.size());
    const RayDiffResult d = backend.impl().run([&] {
      return run_ray_diff(scene.impl().scene, r, backend.impl().built(), reference.impl().built(),
                          occluded);
    });
    DiffReport out;
    out.rays = d.rays;
    out.agree = d.agree;
    out.ties = d.ties;
    out.mismatches = d.mismatches;
    out.backend_right = d.bvh_right;
    out.reference_right = d.embree_right;
    out.both_right = d.both_right;
    out.both_wrong = d.both_wrong;
    out.backend_malformed = d.bvh_malformed;
    out.reference_malformed = d.embree_malformed;
    out.max_rel_t_error = d.max_rel_t_error;
    out.verdicts.reserve(d.verdicts.size());
    for (RayVerdict v : d.verdicts) out.verdicts.push_back(Verdict(uint8_t(v)));
    RayDiffLabels labels;
    labels.backend = backend.impl().built().info().name;
    labels.reference = reference.impl().built().info().name;
    labels.occluded = occluded;
    labels.source = "caller's rays";
    out.summary = ray_diff_summary(d, labels);
    return out;
  });
}

Image render(const Scene& scene, const Backend& backend, int width, int height) {
  if (width < 0 || height < 0) throw std::invalid_argument("render: negative image size");
  if (width > kMaxImageSide || height > kMaxImageSide)
    throw std::invalid_argument("render: image size above " + std::to_string(kMaxImageSide));
  return translate_errors([&] {
    const hprt::Scene& s = scene.impl().scene;
    const Camera camera = override_camera(s.camera, width, height, 0.0f);
    const Framebuffer fb =
        backend.impl().run([&] { return render_whitted(s, camera, backend.impl().built()); });
    Image img;
    img.width = fb.width();
    img.height = fb.height();
    img.rgb.reserve(3 * fb.pixels().size());
    for (const Vec3f& p : fb.pixels()) img.rgb.insert(img.rgb.end(), {p.x, p.y, p.z});
    return img;
  });
}

}  // namespace hprt::api
