// Midpoint subdivision (1 -> 4 triangles per level) to a target count. Edge
// midpoints are shared through an edge table in compressed-row form (edges
// bucketed by their lower vertex, sorted, deduplicated), so neighbouring
// triangles reuse one midpoint vertex and a closed mesh stays closed.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "core/error.h"
#include "meshgen/mesh_generators.h"

namespace hprt {
namespace {

// Edge table: edge (a < b) lives in bucket a; its id is start[a] + rank in bucket.
class EdgeTable {
 public:
  EdgeTable(size_t vertices, std::span<const Vec3u> tris) : offset_(vertices + 1, 0) {
    for (const Vec3u& t : tris)
      for (int k = 0; k < 3; ++k) ++offset_[std::min(t[k], t[(k + 1) % 3]) + 1];
    for (size_t v = 0; v < vertices; ++v) offset_[v + 1] += offset_[v];
    other_.resize(offset_[vertices]);
    std::vector<size_t> fill(offset_.begin(), offset_.end() - 1);
    for (const Vec3u& t : tris)
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = t[k], b = t[(k + 1) % 3];
        other_[fill[std::min(a, b)]++] = std::max(a, b);
      }
    unique_.resize(vertices);
    start_.resize(vertices + 1, 0);
    for (size_t v = 0; v < vertices; ++v) {
      auto first = other_.begin() + offset_[v], last = other_.begin() + offset_[v + 1];
      std::sort(first, last);
      unique_[v] = uint32_t(std::unique(first, last) - first);
      start_[v + 1] = start_[v] + unique_[v];
    }
  }
  size_t size() const { return start_.back(); }
  size_t id(uint32_t a, uint32_t b) const {
    if (b < a) std::swap(a, b);
    const auto first = other_.begin() + offset_[a];
    return start_[a] + size_t(std::lower_bound(first, first + unique_[a], b) - first);
  }
  // Calls f(id, a, b) for every edge.
  template <typename F>
  void for_each(F&& f) const {
    for (size_t v = 0; v + 1 < start_.size(); ++v)
      for (uint32_t k = 0; k < unique_[v]; ++k)
        f(start_[v] + k, uint32_t(v), other_[offset_[v] + k]);
  }

 private:
  std::vector<size_t> offset_;
  std::vector<uint32_t> other_;
  std::vector<uint32_t> unique_;
  std::vector<size_t> start_;
};

void subdivide_once(TriangleMesh& mesh) {
  const size_t nv = mesh.positions.size();
  const EdgeTable edges(nv, mesh.triangles);
  if (nv + edges.size() > std::numeric_limits<uint32_t>::max())
    throw InputError(mesh.name, "subdivision would need more than 2^32 vertices");
  std::vector<Vec3f> positions;
  positions.reserve(nv + edges.size() + 1);
  positions.assign(std::as_const(mesh).positions.begin(), std::as_const(mesh).positions.end());
  positions.resize(nv + edges.size());
  edges.for_each([&](size_t e, uint32_t a, uint32_t b) {
    positions[nv + e] = Vec3f((Vec3d(mesh.positions[a]) + Vec3d(mesh.positions[b])) * 0.5);
  });
  std::vector<Vec3u> tris;
  tris.reserve(4 * mesh.triangles.size());
  for (const Vec3u& t : mesh.triangles) {
    const uint32_t ab = uint32_t(nv + edges.id(t[0], t[1]));
    const uint32_t bc = uint32_t(nv + edges.id(t[1], t[2]));
    const uint32_t ca = uint32_t(nv + edges.id(t[2], t[0]));
    tris.push_back(Vec3u{{t[0], ab, ca}});
    tris.push_back(Vec3u{{ab, t[1], bc}});
    tris.push_back(Vec3u{{ca, bc, t[2]}});
    tris.push_back(Vec3u{{ab, bc, ca}});
  }
  mesh.positions = std::move(positions);
  mesh.triangles = std::move(tris);
}

}  // namespace

TriangleMesh subdivide_mesh(const TriangleMesh& input, size_t tris) {
  if (input.triangles.empty()) throw InputError(input.name, "mesh has no triangles to subdivide");
  const size_t nv = input.positions.size();
  for (const Vec3u& t : input.triangles)
    if (t[0] >= nv || t[1] >= nv || t[2] >= nv)
      throw InputError(input.name, "triangle index out of range");
  TriangleMesh mesh;
  mesh.name = input.name;
  mesh.material = input.material;
  mesh.positions = input.positions;
  mesh.triangles = input.triangles;
  while (mesh.triangles.size() < tris) subdivide_once(mesh);
  return mesh;
}

}  // namespace hprt
