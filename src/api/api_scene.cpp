#include "api/api_scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <algorithm>

#include "api/api_errors.h"
#include "core/triangle_normal.h"
#include "io/mesh/mesh_reader.h"
#include "io/scene/scene_reader.h"

namespace hprt::api {
namespace {

hprt::TriangleMesh& mesh_at(hprt::Scene& s, uint32_t geom_id) {
  if (geom_id >= s.meshes.size())
    throw std::invalid_argument("no mesh with geom_id " + std::to_string(geom_id));
  return s.meshes[geom_id];
}

// A scene made from arrays frames its meshes with the default lens and a
// head light, as load_scene() does for a bare mesh file.
void frame(hprt::Scene& s) {
  s.camera = framing_camera(s.bounds(), Camera{});
  s.lights = {head_light(s.camera)};
}

}  // namespace

const char* version() { return HPRT_VERSION_STRING; }

MeshArrays load_mesh(const std::string& path) {
  return translate_errors([&] {
    const hprt::TriangleMesh m = hprt::load_mesh(path);
    MeshArrays out;
    const auto* v = reinterpret_cast<const float*>(m.positions.data());
    const auto* i = reinterpret_cast<const uint32_t*>(m.triangles.data());
    out.vertices.assign(v, v + 3 * m.positions.size());
    out.indices.assign(i, i + 3 * m.triangles.size());
    return out;
  });
}

Scene::Scene() : impl_(std::make_unique<Impl>()) {}
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

Scene Scene::from_file(const std::string& path) {
  Scene s;
  s.impl_->scene = translate_errors([&] { return load_scene(path); });
  return s;
}

namespace {

void check_mesh_arrays(std::span<const float> vertices, std::span<const uint32_t> indices) {
  if (vertices.size() % 3 != 0)
    throw std::invalid_argument("add_mesh: vertices.size() is not a multiple of 3");
  if (indices.size() % 3 != 0)
    throw std::invalid_argument("add_mesh: indices.size() is not a multiple of 3");
  const size_t n = vertices.size() / 3;
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= n)
      throw Error("add_mesh: triangle " + std::to_string(i / 3) + " references vertex " +
                  std::to_string(indices[i]) + " of " + std::to_string(n));
}

static_assert(sizeof(Vec3f) == 3 * sizeof(float) && sizeof(Vec3u) == 3 * sizeof(uint32_t));

// The public arrays as hprt's records (3 floats = Vec3f, 3 uint32 = Vec3u).
const Vec3f* as_points(std::span<const float> v) {
  return reinterpret_cast<const Vec3f*>(v.data());
}
const Vec3u* as_triangles(std::span<const uint32_t> i) {
  return reinterpret_cast<const Vec3u*>(i.data());
}

uint32_t add_to(hprt::Scene& scene, hprt::TriangleMesh mesh) {
  if (scene.meshes.size() >= kInvalidId) throw Error("add_mesh: too many meshes");
  mesh.name = "mesh " + std::to_string(scene.meshes.size());
  scene.add_mesh(std::move(mesh));
  frame(scene);
  return uint32_t(scene.meshes.size() - 1);
}

}  // namespace

uint32_t Scene::add_mesh(std::span<const float> vertices, std::span<const uint32_t> indices) {
  check_mesh_arrays(vertices, indices);
  hprt::TriangleMesh m;
  m.positions.reserve(vertices.size() / 3 + 1);  // Embree's padding (pad_for_embree)
  m.positions.assign(as_points(vertices), as_points(vertices) + vertices.size() / 3);
  m.triangles.assign(as_triangles(indices), as_triangles(indices) + indices.size() / 3);
  return add_to(impl_->scene, std::move(m));
}

uint32_t Scene::add_mesh_shared(std::span<const float> vertices,
                                std::span<const uint32_t> indices) {
  check_mesh_arrays(vertices, indices);
  hprt::TriangleMesh m;
  m.positions = SharedArray<Vec3f>::view(as_points(vertices), vertices.size() / 3);
  m.triangles = SharedArray<Vec3u>::view(as_triangles(indices), indices.size() / 3);
  return add_to(impl_->scene, std::move(m));
}

void Scene::set_vertices(uint32_t geom_id, std::span<const float> vertices) {
  hprt::TriangleMesh& m = mesh_at(impl_->scene, geom_id);
  if (vertices.size() != 3 * m.vertex_count())
    throw std::invalid_argument("set_vertices: expected " + std::to_string(3 * m.vertex_count()) +
                                " floats (the mesh's vertex count x 3), got " +
                                std::to_string(vertices.size()));
  if (m.positions.is_view())
    m.positions = SharedArray<Vec3f>::view(as_points(vertices), vertices.size() / 3);
  else
    std::copy_n(as_points(vertices), m.positions.size(), m.positions.data());
}

bool Scene::shared(uint32_t geom_id) const {
  return mesh_at(impl_->scene, geom_id).positions.is_view();
}

size_t Scene::mesh_count() const { return impl_->scene.meshes.size(); }
size_t Scene::triangle_count() const { return impl_->scene.triangle_count(); }
size_t Scene::vertex_count(uint32_t geom_id) const {
  return mesh_at(impl_->scene, geom_id).vertex_count();
}

std::span<const float> Scene::vertices(uint32_t geom_id) const {
  const hprt::TriangleMesh& m = mesh_at(impl_->scene, geom_id);
  return {reinterpret_cast<const float*>(m.positions.data()), 3 * m.positions.size()};
}

std::span<const uint32_t> Scene::indices(uint32_t geom_id) const {
  const hprt::TriangleMesh& m = mesh_at(impl_->scene, geom_id);
  return {reinterpret_cast<const uint32_t*>(m.triangles.data()), 3 * m.triangles.size()};
}

void Scene::normals(uint32_t geom_id, std::span<float> out) const {
  const hprt::TriangleMesh& m = mesh_at(impl_->scene, geom_id);
  if (out.size() < 3 * m.triangle_count())
    throw std::invalid_argument("normals: fewer than 3 floats per triangle");
  tbb::parallel_for(tbb::blocked_range<size_t>(0, m.triangle_count(), 16384),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t t = r.begin(); t != r.end(); ++t)
                        triangle_normal(m, uint32_t(t), out.data() + 3 * t);
                    });
}

std::array<float, 6> Scene::bounds() const {
  const AABB b = impl_->scene.bounds();
  return {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z};
}

}  // namespace hprt::api
