#include "bvh/intersect/ray_triangle_exact.h"

#include <atomic>

#include "core/exact_arith.h"

namespace hprt {
namespace {

using exact::difference;
using exact::FixedExpansion;
using exact::product;
using exact::scale;
using exact::subtract;

std::atomic<uint64_t> g_fallbacks{0};

using Exact3 = FixedExpansion<2>[3];  // a vertex minus the origin, exactly

// (q x p) as expansions.
struct Cross {
  FixedExpansion<16> x, y, z;
};
Cross cross(const Exact3& q, const Exact3& p) {
  return {difference(product(q[1], p[2]), product(q[2], p[1])),
          difference(product(q[2], p[0]), product(q[0], p[2])),
          difference(product(q[0], p[1]), product(q[1], p[0]))};
}

// d . c with float d.
FixedExpansion<96> dot(const double (&d)[3], const Cross& c) {
  FixedExpansion<96> r;
  r.add(scale(c.x, d[0]));
  r.add(scale(c.y, d[1]));
  r.add(scale(c.z, d[2]));
  return r;
}

// a . c with exact a.
FixedExpansion<192> dot(const Exact3& a, const Cross& c) {
  FixedExpansion<192> r;
  r.add(product(c.x, a[0]));
  r.add(product(c.y, a[1]));
  r.add(product(c.z, a[2]));
  return r;
}

// Sign of d_i (q_j - p_j) - d_j (q_i - p_i).
int sheared_difference_sign(const double (&d)[3], const float (&p)[3], const float (&q)[3], int i,
                            int j) {
  return difference(scale(subtract(q[j], p[j]), d[i]), scale(subtract(q[i], p[i]), d[j])).sign();
}

}  // namespace

bool watertight_exact(const WatertightRay& ray, const float (&v)[3][3], const EdgeFunctions& f,
                      float tnear, float tfar, TriangleHit& hit) {
  g_fallbacks.fetch_add(1, std::memory_order_relaxed);
  const int axis[3] = {ray.kx, ray.ky, ray.kz};
  double d[3];
  Exact3 rel[3];
  for (int a = 0; a < 3; ++a) {
    d[a] = ray.dir[axis[a]];
    for (int k = 0; k < 3; ++k) rel[k][a] = subtract(v[k][a], ray.org[axis[a]]);
  }
  // (p, q) of U, V, W; T = d . ((q - o) x (p - o)) = d_z * edge function.
  static constexpr int kEdge[3][2] = {{1, 2}, {2, 0}, {0, 1}};
  Cross c[3];
  FixedExpansion<96> t_edge[3];
  int sign[3];
  for (int e = 0; e < 3; ++e) {
    const int p = kEdge[e][0], q = kEdge[e][1];
    c[e] = cross(rel[q], rel[p]);
    t_edge[e] = dot(d, c[e]);
    sign[e] = t_edge[e].sign();
    // On the edge's line: the perturbed ray's side, Y_q - Y_p, then X_p - X_q
    // (times d_z, which T carries too).
    if (sign[e] == 0) sign[e] = sheared_difference_sign(d, v[p], v[q], 2, 1);
    if (sign[e] == 0) sign[e] = sheared_difference_sign(d, v[q], v[p], 2, 0);
  }
  if (sign[0] == 0 || sign[0] != sign[1] || sign[0] != sign[2]) return false;
  // The double values' signs are sign(T) * sign(d_z): where none disagrees
  // and their sum is not 0, the double formula, as if the bound had decided.
  const double s = d[2] > 0.0 ? sign[0] : -sign[0];
  if (f.e[0] * s >= 0.0 && f.e[1] * s >= 0.0 && f.e[2] * s >= 0.0 &&
      f.e[0] + f.e[1] + f.e[2] != 0.0)
    return edge_function_hit(f, ray.sz, tnear, tfar, hit);
  FixedExpansion<288> det;
  for (const auto& te : t_edge) det.add(te);
  // t = v0' . ((v2 - o) x (v1 - o)) / det; c[0] is that cross product.
  const double det_d = det.estimate();
  const float t = float(dot(rel[0], c[0]).estimate() / det_d);
  if (!(tnear < t && t <= tfar)) return false;
  hit.t = t;
  hit.u = float(t_edge[1].estimate() / det_d);  // weight of v1
  hit.v = float(t_edge[2].estimate() / det_d);  // weight of v2
  return true;
}

uint64_t exact_fallback_count() { return g_fallbacks.load(std::memory_order_relaxed); }

}  // namespace hprt
