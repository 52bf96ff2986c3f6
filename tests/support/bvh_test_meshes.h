// Meshes generated in code for the BVH tests (random soup, terrain grid,
// closed icosphere, coincident centroids, duplicates, exponentially spaced,
// degenerate/NaN triangles) and the tree invariant checker every builder
// test uses.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bvh/builders/build_tree.h"
#include "bvh/input/prim_info.h"
#include "core/scene.h"
#include "core/splitmix64.h"
#include "core/triangle_mesh.h"

namespace hprt::test {

using Rng = SplitMix64;

inline void add_triangle(TriangleMesh& m, Vec3f a, Vec3f b, Vec3f c) {
  const uint32_t base = static_cast<uint32_t>(m.positions.size());
  m.positions.push_back(a);
  m.positions.push_back(b);
  m.positions.push_back(c);
  m.triangles.push_back(Vec3u{{base, base + 1, base + 2}});
}

// n triangles of edge ~size scattered in the unit cube.
inline TriangleMesh random_soup(size_t n, uint64_t seed, float size = 0.02f) {
  TriangleMesh m;
  m.name = "soup";
  Rng r(seed);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f p{r.uniform(), r.uniform(), r.uniform()};
    auto jitter = [&] {
      return Vec3f{(r.uniform() - 0.5f) * size, (r.uniform() - 0.5f) * size,
                   (r.uniform() - 0.5f) * size};
    };
    add_triangle(m, p + jitter(), p + jitter(), p + jitter());
  }
  return m;
}

// A (nx x ny) heightfield terrain, 2 triangles per cell, shared vertices.
inline TriangleMesh grid(int nx, int ny) {
  TriangleMesh m;
  m.name = "grid";
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const float x = float(i) / nx, y = float(j) / ny;
      m.positions.push_back({x, y, 0.05f * std::sin(11.0f * x) * std::cos(7.0f * y)});
    }
  auto v = [&](int i, int j) { return static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.triangles.push_back(Vec3u{{v(i, j), v(i + 1, j), v(i + 1, j + 1)}});
      m.triangles.push_back(Vec3u{{v(i, j), v(i + 1, j + 1), v(i, j + 1)}});
    }
  return m;
}

// A closed unit icosphere with 20 * 4^subdivisions triangles.
inline TriangleMesh icosphere(int subdivisions) {
  TriangleMesh m;
  m.name = "icosphere";
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  const float base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                             {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                             {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (const auto& p : base) m.positions.push_back(normalize(Vec3f{p[0], p[1], p[2]}));
  const uint32_t faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (const auto& f : faces) m.triangles.push_back(Vec3u{{f[0], f[1], f[2]}});
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mids;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mids.find(key);
      if (it != mids.end()) return it->second;
      const uint32_t id = static_cast<uint32_t>(m.positions.size());
      m.positions.push_back(normalize((m.positions[a] + m.positions[b]) * 0.5f));
      mids.emplace(key, id);
      return id;
    };
    std::vector<Vec3u> next;
    for (const Vec3u& f : m.triangles) {
      const uint32_t a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
      next.push_back(Vec3u{{f[0], a, c}});
      next.push_back(Vec3u{{f[1], b, a}});
      next.push_back(Vec3u{{f[2], c, b}});
      next.push_back(Vec3u{{a, b, c}});
    }
    m.triangles = std::move(next);
  }
  return m;
}

// n triangles of different sizes whose boxes all have their centre at origin.
inline TriangleMesh coincident_centroids(size_t n) {
  TriangleMesh m;
  m.name = "coincident";
  for (size_t i = 0; i < n; ++i) {
    const float a = 0.1f + 0.01f * float(i), b = 0.2f + 0.003f * float(i % 7);
    add_triangle(m, {-a, -b, 0}, {a, -b, 0}, {0, b, 0});
  }
  return m;
}

// `copies` copies of each of `distinct` random triangles.
inline TriangleMesh duplicates(size_t distinct, size_t copies, uint64_t seed) {
  const TriangleMesh src = random_soup(distinct, seed, 0.05f);
  TriangleMesh m = src;
  m.name = "duplicates";
  for (size_t c = 1; c < copies; ++c)
    for (const Vec3u& t : src.triangles) m.triangles.push_back(t);
  return m;
}

// Triangles spanning x in [2^k, 1.5 * 2^k] for k = -n/2 .. n/2 - 1 (n <= 250),
// y and z in [0, 1]: SAH and coarse bins peel a few off per level, so without
// the depth guard the tree would be about n deep (adversarial depth).
inline TriangleMesh exponential_spacing(size_t n) {
  TriangleMesh m;
  m.name = "exponential";
  for (size_t i = 0; i < n; ++i) {
    const float x = std::ldexp(1.0f, static_cast<int>(i) - static_cast<int>(n / 2));
    add_triangle(m, {x, 0, 0}, {1.5f * x, 0, 0}, {x, 1, 1});
  }
  return m;
}

// 6 valid triangles, then degenerate (repeated vertex, collinear), NaN, inf
// and out-of-range ones, interleaved.
inline TriangleMesh with_invalid_triangles() {
  TriangleMesh m;
  m.name = "invalid";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  add_triangle(m, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});    // 0 valid
  add_triangle(m, {0, 0, 0}, {0, 0, 0}, {0, 1, 0});    // 1 repeated vertex
  add_triangle(m, {2, 0, 0}, {3, 0, 0}, {2, 1, 0});    // 2 valid
  add_triangle(m, {0, 0, 0}, {1, 1, 1}, {2, 2, 2});    // 3 collinear
  add_triangle(m, {4, 0, 0}, {5, 0, 0}, {4, 1, 0});    // 4 valid
  add_triangle(m, {nan, 0, 0}, {1, 0, 0}, {0, 1, 0});  // 5 NaN
  add_triangle(m, {6, 0, 0}, {7, 0, 0}, {6, 1, 1});    // 6 valid
  add_triangle(m, {inf, 0, 0}, {1, 0, 0}, {0, 1, 0});  // 7 inf
  add_triangle(m, {8, 0, 0}, {9, 0, 0}, {8, 1, 2});    // 8 valid
  m.triangles.push_back(Vec3u{{0, 1, 9999}});          // 9 index out of range
  add_triangle(m, {0, 5, 0}, {1, 5, 0}, {0, 6, 3});    // 10 valid
  return m;
}

inline PrimInfo prims_of(const TriangleMesh& mesh) {
  Scene s;
  s.add_mesh(mesh);
  return make_prim_info(s);
}

// Checks the canonical layout and tree invariants; returns "" when all hold,
// else the first violation.
inline std::string check_tree(const BuildTree& t, const PrimInfo& p, int max_leaf_size) {
  const size_t n = p.size();
  if (n == 0) return t.nodes.empty() && t.prim_order.empty() ? "" : "empty input, non-empty tree";
  if (t.nodes.empty()) return "no nodes";
  if (t.prim_order.size() != n) return "prim_order size " + std::to_string(t.prim_order.size());
  std::vector<int> seen(n, 0);
  for (uint32_t id : t.prim_order) {
    if (id >= n) return "prim_order index out of range";
    if (seen[id]++) return "primitive " + std::to_string(id) + " twice";
  }
  size_t cursor = 0;
  std::string err;
  // Returns the index one past node i's subtree.
  auto walk = [&](auto&& self, size_t i, int depth) -> size_t {
    if (!err.empty()) return t.nodes.size();
    if (i >= t.nodes.size()) return err = "node index out of range", t.nodes.size();
    if (depth > kMaxBuildDepth) return err = "depth above kMaxBuildDepth", t.nodes.size();
    const BuildNode& nd = t.nodes[i];
    if (nd.is_leaf()) {
      if (nd.count > static_cast<uint32_t>(max_leaf_size)) err = "leaf too big";
      if (nd.first != cursor) err = "leaf ranges not contiguous in preorder";
      AABB u;
      for (uint32_t k = nd.first; k < nd.first + nd.count && k < n; ++k)
        u.extend(p.bounds[t.prim_order[k]]);
      if (!(u == nd.bounds)) err = "leaf box is not the union of its primitives";
      cursor += nd.count;
      return i + 1;
    }
    if (nd.right <= i + 1) return err = "right child not after left", t.nodes.size();
    const size_t after_left = self(self, i + 1, depth + 1);
    if (after_left != nd.right) return err = "not depth-first preorder", t.nodes.size();
    const size_t after = self(self, nd.right, depth + 1);
    if (err.empty()) {
      AABB u = t.nodes[i + 1].bounds;
      u.extend(t.nodes[nd.right].bounds);
      if (!(u == nd.bounds)) err = "inner box is not the union of its children";
    }
    return after;
  };
  const size_t end = walk(walk, 0, 1);
  if (!err.empty()) return err;
  if (end != t.nodes.size()) return "nodes outside the root's subtree";
  if (cursor != n) return "leaves do not cover prim_order";
  return "";
}

}  // namespace hprt::test
