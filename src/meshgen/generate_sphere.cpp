// Sphere generator: every edge of an icosahedron split into m segments, each
// face into m² triangles on a barycentric grid; corner, edge and face-interior
// vertices are numbered once so neighbours share them; then all vertices are
// projected onto the unit sphere. Faces are filled in parallel (disjoint ranges).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "meshgen/mesh_generators.h"

namespace hprt {
namespace {

constexpr double kPhi = 1.6180339887498948482;

// Icosahedron (12 vertices, 20 faces, counter-clockwise seen from outside).
constexpr std::array<std::array<double, 3>, 12> kCorners{{{-1, kPhi, 0},
                                                          {1, kPhi, 0},
                                                          {-1, -kPhi, 0},
                                                          {1, -kPhi, 0},
                                                          {0, -1, kPhi},
                                                          {0, 1, kPhi},
                                                          {0, -1, -kPhi},
                                                          {0, 1, -kPhi},
                                                          {kPhi, 0, -1},
                                                          {kPhi, 0, 1},
                                                          {-kPhi, 0, -1},
                                                          {-kPhi, 0, 1}}};
constexpr std::array<std::array<int, 3>, 20> kFaces{
    {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
     {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
     {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}}};

Vec3d corner(int i) { return {kCorners[i][0], kCorners[i][1], kCorners[i][2]}; }
Vec3f on_sphere(const Vec3d& p) { return Vec3f(normalize(p)); }

}  // namespace

int sphere_segments(size_t tris) {
  int m = std::max(1, int(std::sqrt(double(tris) / 20.0)));
  while (20.0 * m * m < double(tris)) ++m;
  while (m > 1 && 20.0 * (m - 1) * (m - 1) >= double(tris)) --m;
  return m;
}

TriangleMesh generate_sphere(size_t tris) {
  const int m = sphere_segments(tris);
  const size_t mm = size_t(m);
  // The 30 edges, each stored once with its lower corner first.
  std::vector<std::pair<int, int>> edges;
  for (const auto& f : kFaces)
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      const std::pair<int, int> e{std::min(a, b), std::max(a, b)};
      if (std::find(edges.begin(), edges.end(), e) == edges.end()) edges.push_back(e);
    }
  const size_t edge_base = 12;
  const size_t face_base = edge_base + edges.size() * (mm - 1);
  const size_t interior = m >= 3 ? (mm - 1) * (mm - 2) / 2 : 0;

  TriangleMesh mesh;
  mesh.name = "sphere(" + std::to_string(20 * mm * mm) + ")";
  mesh.positions.resize(face_base + kFaces.size() * interior);
  mesh.triangles.resize(kFaces.size() * mm * mm);
  for (int c = 0; c < 12; ++c) mesh.positions[c] = on_sphere(corner(c));
  for (size_t e = 0; e < edges.size(); ++e)
    for (size_t k = 1; k < mm; ++k) {
      const Vec3d a = corner(edges[e].first), b = corner(edges[e].second);
      mesh.positions[edge_base + e * (mm - 1) + k - 1] = on_sphere(a + (b - a) * (double(k) / m));
    }

  // Index of the vertex k segments from corner u along edge (u, v).
  auto edge_vertex = [&](int u, int v, size_t k) -> uint32_t {
    const std::pair<int, int> key{std::min(u, v), std::max(u, v)};
    const size_t e = size_t(std::find(edges.begin(), edges.end(), key) - edges.begin());
    const size_t along = u < v ? k : mm - k;
    return uint32_t(edge_base + e * (mm - 1) + along - 1);
  };

  tbb::parallel_for(size_t{0}, kFaces.size(), [&](size_t f) {
    const int a = kFaces[f][0], b = kFaces[f][1], c = kFaces[f][2];
    const Vec3d pa = corner(a), pb = corner(b), pc = corner(c);
    // Local grid (i along a->b, j along a->c, i + j <= m), row-major in i.
    std::vector<uint32_t> grid((mm + 1) * (mm + 2) / 2);
    auto local = [&](size_t i, size_t j) { return i * (mm + 1) - i * (i - 1) / 2 + j; };
    size_t next = face_base + f * interior;
    for (size_t i = 0; i <= mm; ++i)
      for (size_t j = 0; i + j <= mm; ++j) {
        uint32_t id;
        if (i == 0 && j == 0)
          id = uint32_t(a);
        else if (i == mm)
          id = uint32_t(b);
        else if (j == mm)
          id = uint32_t(c);
        else if (j == 0)
          id = edge_vertex(a, b, i);
        else if (i == 0)
          id = edge_vertex(a, c, j);
        else if (i + j == mm)
          id = edge_vertex(b, c, j);
        else {
          id = uint32_t(next++);
          mesh.positions[id] =
              on_sphere(pa + (pb - pa) * (double(i) / m) + (pc - pa) * (double(j) / m));
        }
        grid[local(i, j)] = id;
      }
    Vec3u* out = mesh.triangles.data() + f * mm * mm;
    for (size_t i = 0; i < mm; ++i)
      for (size_t j = 0; i + j < mm; ++j) {
        *out++ = Vec3u{{grid[local(i, j)], grid[local(i + 1, j)], grid[local(i, j + 1)]}};
        if (i + j + 1 < mm)
          *out++ = Vec3u{{grid[local(i + 1, j)], grid[local(i + 1, j + 1)], grid[local(i, j + 1)]}};
      }
  });
  return mesh;
}

}  // namespace hprt
