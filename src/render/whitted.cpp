// Algorithm 6 (Whitted), wavefront per tile: primary batch -> intersect ->
// shade (shadow batch -> occluded -> add unoccluded light) -> reflection batch
// -> intersect -> ... until no path is left or scene.max_depth is reached.
// Batches live in scratch buffers taken from a pool per tile task, so nothing
// is allocated per ray once the pool is warm.
#include "render/whitted.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "core/ray_offset.h"
#include "render/progress.h"
#include "render/shading.h"
#include "render/tile_scheduler.h"

namespace hprt {
namespace {

struct PathState {
  uint32_t pixel;  // index into the tile's accumulator
  float weight;    // product of reflectivities so far
};

struct Scratch {
  std::vector<Ray> rays, next_rays;
  std::vector<PathState> paths, next_paths;
  std::vector<Hit> hits;
  std::vector<Ray> shadow_rays;
  std::vector<Vec3f> shadow_light;  // contribution if unoccluded
  std::vector<uint32_t> shadow_pixel;
  std::vector<uint32_t> shadow_light_index;
  std::vector<uint32_t> light_start;  // counting sort of the shadow batch by light
  std::vector<Ray> sorted_rays;
  std::vector<Vec3f> sorted_light;
  std::vector<uint32_t> sorted_pixel;
  std::vector<uint8_t> occluded;
  std::vector<Vec3f> accum;
};

// Scratch buffers handed to tile tasks. A pool rather than thread-local
// storage: a worker waiting inside a backend's nested parallel_for may start
// another tile, which must not get the same buffers.
class ScratchPool {
 public:
  std::unique_ptr<Scratch> take() {
    std::lock_guard lock(mutex_);
    if (free_.empty()) return std::make_unique<Scratch>();
    auto s = std::move(free_.back());
    free_.pop_back();
    return s;
  }
  void give_back(std::unique_ptr<Scratch> s) {
    std::lock_guard lock(mutex_);
    free_.push_back(std::move(s));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<Scratch>> free_;
};

// Surface data at a hit: position from barycentrics (more accurate than
// org + t dir far from the origin), geometric and shading normals turned
// toward the incoming ray.
struct SurfaceHit {
  Vec3f p;
  Vec3f ng;
  Vec3f ns;
  const Material* material;
};

inline SurfaceHit surface_at(const Scene& scene, const Ray& ray, const Hit& hit) {
  const TriangleMesh& mesh = scene.meshes[hit.geom_id];
  const Vec3u& tri = mesh.triangles[hit.prim_id];
  const Vec3f& a = mesh.positions[tri[0]];
  const Vec3f& b = mesh.positions[tri[1]];
  const Vec3f& c = mesh.positions[tri[2]];
  const float w = 1.0f - hit.u - hit.v;
  SurfaceHit s;
  s.material = &mesh.material;
  s.p = a * w + b * hit.u + c * hit.v;
  s.ng = normalize(cross(b - a, c - a));
  if (dot(s.ng, ray.dir) > 0.0f) s.ng = -s.ng;
  s.ns = s.ng;
  if (mesh.normals.size() == mesh.positions.size()) {
    const Vec3f n =
        mesh.normals[tri[0]] * w + mesh.normals[tri[1]] * hit.u + mesh.normals[tri[2]] * hit.v;
    const float len = length(n);
    if (len > 0.0f && std::isfinite(len)) {
      s.ns = n / len;
      if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
    }
  }
  return s;
}

class WhittedTracer {
 public:
  WhittedTracer(const Scene& scene, const Camera& camera, const Intersector& intersector)
      : scene_(scene),
        rays_(camera),
        isect_(intersector),
        max_depth_(std::max(0, scene.max_depth)) {}

  void render_tile(const Tile& tile, Scratch& s, Framebuffer& fb, RenderStats& stats) const {
    const int tw = tile.x1 - tile.x0;
    const size_t n_pixels = size_t(tile.pixel_count());
    s.accum.assign(n_pixels, Vec3f(0.0f));
    s.rays.clear();
    s.paths.clear();
    // 4x4 pixel blocks, so each group of 16 consecutive rays (a packet, when
    // the backend traces packets) covers a square patch of the image.
    for (int by = tile.y0; by < tile.y1; by += 4)
      for (int bx = tile.x0; bx < tile.x1; bx += 4)
        for (int y = by; y < std::min(by + 4, tile.y1); ++y)
          for (int x = bx; x < std::min(bx + 4, tile.x1); ++x) {
            s.rays.push_back(rays_.pixel_ray(x, y));
            s.paths.push_back({uint32_t((y - tile.y0) * tw + (x - tile.x0)), 1.0f});
          }
    stats.primary_rays += s.rays.size();

    for (int depth = 0; !s.rays.empty(); ++depth) {
      s.hits.resize(s.rays.size());
      isect_.intersect(s.rays, s.hits);
      shade(s, depth, stats);
      std::swap(s.rays, s.next_rays);
      std::swap(s.paths, s.next_paths);
      stats.reflection_rays += s.rays.size();
    }

    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x)
        fb.at(x, y) = s.accum[size_t((y - tile.y0) * tw + (x - tile.x0))];
  }

 private:
  // Shades the current batch: misses take the background, hits add ambient
  // at once and light after the shadow batch; reflective hits fill next_rays.
  void shade(Scratch& s, int depth, RenderStats& stats) const {
    s.shadow_rays.clear();
    s.shadow_light.clear();
    s.shadow_pixel.clear();
    s.shadow_light_index.clear();
    s.next_rays.clear();
    s.next_paths.clear();
    for (size_t i = 0; i < s.rays.size(); ++i) {
      const Ray& ray = s.rays[i];
      const Hit& hit = s.hits[i];
      const PathState path = s.paths[i];
      if (!hit.hit()) {
        s.accum[path.pixel] += scene_.background * path.weight;
        continue;
      }
      const SurfaceHit sh = surface_at(scene_, ray, hit);
      const Material& m = *sh.material;
      s.accum[path.pixel] += ambient_term(scene_.ambient, m) * path.weight;
      const Vec3f v = -normalize(ray.dir);
      const Vec3f origin = offset_ray(sh.p, sh.ng, kBarycentricHitIntScale);
      for (uint32_t li = 0; li < scene_.lights.size(); ++li) {
        const Light& light = scene_.lights[li];
        const ShadowSegment seg = shadow_segment(light, origin);
        const Vec3f c = direct_term(m, sh.ns, seg.to_light, v, light.intensity) * path.weight;
        if (!(c.x > 0.0f || c.y > 0.0f || c.z > 0.0f)) continue;
        Ray sr;
        sr.org = origin;
        sr.dir = seg.dir;
        sr.tnear = 0.0f;
        sr.tfar = seg.tfar;
        s.shadow_rays.push_back(sr);
        s.shadow_light.push_back(c);
        s.shadow_pixel.push_back(path.pixel);
        s.shadow_light_index.push_back(li);
      }
      const float w = path.weight * m.reflectivity;
      if (depth < max_depth_ && w >= kMinPathWeight) {
        Vec3f r = reflect(v * -1.0f, sh.ns);
        // An interpolated normal can send the mirror ray below the surface;
        // the geometric normal's mirror direction never does.
        if (dot(r, sh.ng) <= 0.0f) r = reflect(v * -1.0f, sh.ng);
        Ray rr;
        rr.org = origin;
        rr.dir = r;
        rr.tnear = 0.0f;
        s.next_rays.push_back(rr);
        s.next_paths.push_back({path.pixel, w});
      }
    }
    if (s.shadow_rays.empty()) return;
    group_by_light(s);
    s.occluded.resize(s.shadow_rays.size());
    isect_.occluded(s.shadow_rays, s.occluded);
    stats.shadow_rays += s.shadow_rays.size();
    for (size_t k = 0; k < s.shadow_rays.size(); ++k)
      if (!s.occluded[k]) s.accum[s.shadow_pixel[k]] += s.shadow_light[k];
  }

  // Orders the shadow batch by light (stable: pixel order within a light), so
  // that consecutive rays share a direction and a backend can trace them as
  // packets; with rays interleaved by light no 16-ray group is coherent.
  void group_by_light(Scratch& s) const {
    const size_t lights = scene_.lights.size();
    if (lights < 2) return;
    s.light_start.assign(lights + 1, 0);
    for (uint32_t li : s.shadow_light_index) ++s.light_start[li + 1];
    for (size_t l = 1; l <= lights; ++l) s.light_start[l] += s.light_start[l - 1];
    const size_t n = s.shadow_rays.size();
    s.sorted_rays.resize(n);
    s.sorted_light.resize(n);
    s.sorted_pixel.resize(n);
    for (size_t k = 0; k < n; ++k) {
      const uint32_t to = s.light_start[s.shadow_light_index[k]]++;
      s.sorted_rays[to] = s.shadow_rays[k];
      s.sorted_light[to] = s.shadow_light[k];
      s.sorted_pixel[to] = s.shadow_pixel[k];
    }
    std::swap(s.shadow_rays, s.sorted_rays);
    std::swap(s.shadow_light, s.sorted_light);
    std::swap(s.shadow_pixel, s.sorted_pixel);
  }

  const Scene& scene_;
  CameraRays rays_;
  const Intersector& isect_;
  int max_depth_;
};

}  // namespace

Framebuffer render_whitted(const Scene& scene, const Camera& camera, const Intersector& intersector,
                           RenderStats* stats, const RenderOptions& options) {
  Framebuffer fb(camera.width, camera.height);
  const std::vector<Tile> tiles = make_tiles(camera.width, camera.height, options.tile_size);
  const WhittedTracer tracer(scene, camera, intersector);
  ScratchPool pool;
  std::atomic<uint64_t> primary{0}, shadow{0}, reflection{0};
  for_each_tile(tiles, [&](const Tile& tile) {
    std::unique_ptr<Scratch> scratch = pool.take();
    RenderStats tile_stats;
    tracer.render_tile(tile, *scratch, fb, tile_stats);
    pool.give_back(std::move(scratch));
    primary.fetch_add(tile_stats.primary_rays, std::memory_order_relaxed);
    shadow.fetch_add(tile_stats.shadow_rays, std::memory_order_relaxed);
    reflection.fetch_add(tile_stats.reflection_rays, std::memory_order_relaxed);
    if (options.progress) options.progress->advance();
  });
  if (stats) {
    stats->primary_rays = primary.load();
    stats->shadow_rays = shadow.load();
    stats->reflection_rays = reflection.load();
  }
  return fb;
}

}  // namespace hprt
