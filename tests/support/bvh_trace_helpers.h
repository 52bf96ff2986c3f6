// Shared by the traversal/backend/hard-case tests: build a Bvh2 from a mesh
// with the real builders, random and coherent ray sets, and a brute-force
// closest/any hit over all triangles with the same triangle test.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "bvh/builders/builders.h"
#include "bvh/layout/flatten_bvh2.h"
#include "bvh/traverse/traverse_bvh2.h"
#include "tests/support/bvh_test_meshes.h"

namespace hprt::test {

// Bit-identical answers (t, u, v and ids): what two traversals of one ray
// must agree on.
inline constexpr float kInf = std::numeric_limits<float>::infinity();

inline bool same_hit(const Hit& a, const Hit& b) { return std::memcmp(&a, &b, sizeof(Hit)) == 0; }

inline Scene scene_of(std::vector<TriangleMesh> meshes) {
  Scene s;
  for (auto& m : meshes) s.add_mesh(std::move(m));
  return s;
}

struct BuiltBvh {
  Scene scene;
  PrimInfo prims;
  BuildTree tree;
  Bvh2 bvh;
};

inline BuiltBvh build_flat(std::vector<TriangleMesh> meshes, const BuildOptions& options) {
  BuiltBvh b;
  for (auto& m : meshes) b.scene.add_mesh(std::move(m));
  b.prims = make_prim_info(b.scene);
  b.tree = build_tree(b.prims, options);
  b.bvh = flatten(b.tree, b.prims, b.scene);
  return b;
}

inline Vec3f random_direction(Rng& r) {
  for (;;) {
    const Vec3f d{2 * r.uniform() - 1, 2 * r.uniform() - 1, 2 * r.uniform() - 1};
    const float l = dot(d, d);
    if (l > 1e-4f && l <= 1.0f) return d;
  }
}

// Origins in the box enlarged by half its size, directions uniform.
inline std::vector<Ray> random_rays(const AABB& box, size_t n, uint64_t seed) {
  Rng r(seed);
  const Vec3f lo = box.min - box.diagonal() * 0.5f, ext = box.diagonal() * 2.0f;
  std::vector<Ray> rays(n);
  for (Ray& ray : rays) {
    ray.org = lo + Vec3f{r.uniform() * ext.x, r.uniform() * ext.y, r.uniform() * ext.z};
    ray.dir = random_direction(r);
  }
  return rays;
}

// A w x h pinhole grid from outside the box towards its centre.
inline std::vector<Ray> coherent_rays(const AABB& box, int w, int h) {
  const Vec3f c = box.center();
  const float radius = 0.5f * length(box.diagonal());
  const Vec3f eye = c + Vec3f{0.3f, 0.4f, 1.0f} * (2.5f * radius);
  const Vec3f fwd = normalize(c - eye);
  const Vec3f right = normalize(cross(fwd, Vec3f{0, 1, 0}));
  const Vec3f up = cross(right, fwd);
  std::vector<Ray> rays;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      Ray ray;
      ray.org = eye;
      ray.dir = fwd + right * (0.5f * (2.0f * (i + 0.5f) / w - 1.0f)) +
                up * (0.5f * (2.0f * (j + 0.5f) / h - 1.0f));
      rays.push_back(ray);
    }
  return rays;
}

// The leaf (its own verts block) of each triangle of a flat layout, by leaf
// index.
inline std::vector<LeafRange> leaf_of_each(const Bvh2& bvh) {
  std::vector<LeafRange> out(bvh.triangles.size());
  for (const BinaryNode& n : bvh.nodes)
    if (n.is_leaf() && n.count > 0)
      for (uint32_t j = n.index; j < n.index + n.count && j < out.size(); ++j)
        out[j] = LeafRange::whole(n.index, n.count);
  return out;
}

// Closest hit over every triangle of the flat layout, in leaf order, with
// the same test and the same (tnear, tfar] update as the traversal: the
// smallest (t, leaf index).
template <typename Test>
bool brute_force(const Bvh2& bvh, const Ray& ray, Hit& hit) {
  if (!ray_is_valid(ray)) return false;
  const auto p = Test::prepare(ray);
  const std::vector<LeafRange> leaves = leaf_of_each(bvh);
  float tfar = ray.tfar;
  bool found = false;
  for (uint32_t i = 0; i < bvh.triangles.size(); ++i) {
    TriangleHit h;
    if (Test::intersect(p, bvh.triangles, leaves[i], i, ray.tnear, tfar, h)) {
      if (found && h.t == tfar) continue;  // a tie keeps the lower leaf index
      tfar = h.t;
      found = true;
      hit = Hit{h.t, h.u, h.v, bvh.triangles.refs[i].geom_id, bvh.triangles.refs[i].prim_id};
    }
  }
  return found;
}

}  // namespace hprt::test
