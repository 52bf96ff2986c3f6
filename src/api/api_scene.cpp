#include "api/api_scene.h"
#include "api/api_errors.h"
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

Scene::Scene() : impl_(std::make_unique<Impl>()) {}
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

Scene Scene::from_file(const std::string& path) {
  Scene s;
  s.impl_->scene = translate_errors([&] { return load_scene(path); });
  return s;
}

uint32_t Scene::add_mesh(std::span<const float> vertices, std::span<const uint32_t> indices) {
  if (vertices.size() % 3 != 0)
    throw std::invalid_argument("add_mesh: vertices.size() is not a multiple of 3");
  if (indices.size() % 3 != 0)
    throw std::invalid_argument("add_mesh: indices.size() is not a multiple of 3");
  if (impl_->scene.meshes.size() >= kInvalidId) throw Error("add_mesh: too many meshes");
  hprt::TriangleMesh m;
  m.name = "mesh " + std::to_string(impl_->scene.meshes.size());
  m.positions.reserve(vertices.size() / 3 + 1);  // Embree's padding (pad_for_embree)
  for (size_t i = 0; i < vertices.size(); i += 3)
    m.positions.emplace_back(vertices[i], vertices[i + 1], vertices[i + 2]);
  m.triangles.reserve(indices.size() / 3);
  for (size_t i = 0; i < indices.size(); i += 3)
    m.triangles.push_back(Vec3u{{indices[i], indices[i + 1], indices[i + 2]}});
  impl_->scene.add_mesh(std::move(m));
  frame(impl_->scene);
  return uint32_t(impl_->scene.meshes.size() - 1);
}

void Scene::set_vertices(uint32_t geom_id, std::span<const float> vertices) {
  hprt::TriangleMesh& m = mesh_at(impl_->scene, geom_id);
  if (vertices.size() != 3 * m.positions.size())
    throw std::invalid_argument("set_vertices: expected " + std::to_string(3 * m.positions.size()) +
                                " floats (the mesh's vertex count x 3), got " +
                                std::to_string(vertices.size()));
  for (size_t i = 0; i < m.positions.size(); ++i)
    m.positions[i] = Vec3f(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
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

std::array<float, 6> Scene::bounds() const {
  const AABB b = impl_->scene.bounds();
  return {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z};
}

}  // namespace hprt::api
