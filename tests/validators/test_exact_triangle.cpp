// The watertight test's decisions against the exact arbiter on rays aimed
// within 1e-5 .. 1e-17 of a triangle's edges and vertices (where the double
// error bound of the test is tight and the exact fallback takes over): the
// test hits exactly when the arbiter finds the ray's line strictly inside
// the triangle, whatever the distance; on an edge or vertex exactly, the
// fill rule decides and is checked elsewhere (tests/bvh, tests/backends).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bvh/intersect/ray_triangle.h"
#include "bvh/intersect/ray_triangle_exact.h"
#include "core/splitmix64.h"
#include "validators/arbiter.h"
#include "validators/exact_expansion.h"

namespace hprt {
namespace {

using exact::Expansion;

TEST(ExactTriangleTest, AgreesWithTheArbiterNearEdgesAndVertices) {
  SplitMix64 rng(9);
  const auto u = [&] { return rng.uniform() - 0.5f; };
  const uint64_t fallbacks_before = exact_fallback_count();
  int strict = 0, disagree = 0;
  for (int i = 0; i < 40000; ++i) {
    const float scale = std::ldexp(1.0f, int(rng.next() % 40) - 20);
    const Vec3f off{u() * 100.0f, u() * 100.0f, u() * 100.0f};
    const Vec3f v[3] = {off + Vec3f{u(), u(), u()} * scale, off + Vec3f{u(), u(), u()} * scale,
                        off + Vec3f{u(), u(), u()} * scale};
    // A point on an edge (or at a vertex), pushed off by a tiny amount.
    const int e = int(rng.next() % 3);
    const float s = (i % 5 == 0) ? 0.0f : rng.uniform();
    const Vec3f on = v[e] + (v[(e + 1) % 3] - v[e]) * s;
    const float push = std::ldexp(1.0f, -int(17 + rng.next() % 40)) * scale;
    const Vec3f target = on + Vec3f{u(), u(), u()} * push;
    Ray r;
    r.org = target + Vec3f{u(), u(), 1.0f} * (3.0f * scale);
    r.dir = target - r.org;
    const CandidateResult exact = arbitrate_triangle(r, v[0], v[1], v[2]);
    if (!exact.valid || exact.zero_edges > 0) continue;  // degenerate, or the fill rule's case
    TriangleHit h;
    const bool hit =
        WatertightTest::intersect(WatertightTest::prepare(r), v[0], v[1], v[2], r.tnear, r.tfar, h);
    ++strict;
    disagree += hit != exact.hit;
  }
  EXPECT_GT(strict, 30000);
  EXPECT_EQ(disagree, 0);
  // Rays this close to an edge are what the exact fallback is for.
  EXPECT_GT(exact_fallback_count() - fallbacks_before, 100u);
}

// The error bounds themselves (the scalar test's per triangle, the lanes'
// per ray): for random rays and triangles at every scale and offset, and for
// rays exactly through an edge or vertex (where the rounding error is all
// there is), |U_double - U| <= bound, checked exactly as |d_z U_double - T|
// <= d_z bound with T = d_z U in expansion arithmetic.
TEST(ExactTriangleTest, DoubleEdgeFunctionsStayWithinTheirBound) {
  SplitMix64 rng(17);
  const auto u = [&] { return rng.uniform() - 0.5f; };
  int checked = 0;
  for (int i = 0; i < 30000; ++i) {
    const float scale = std::ldexp(1.0f, int(rng.next() % 60) - 30);
    const Vec3f off = Vec3f{u(), u(), u()} * std::ldexp(1.0f, int(rng.next() % 50) - 20);
    Vec3f v[3];
    for (Vec3f& p : v) p = off + Vec3f{u(), u(), u()} * scale;
    const float s = (i % 3 == 0) ? 0.0f : (i % 3 == 1 ? 0.5f : rng.uniform());
    const Vec3f target = v[0] + (v[1] - v[0]) * s;
    Ray r;
    r.org = target + Vec3f{u(), u(), u()} * (scale * std::ldexp(1.0f, int(rng.next() % 20)));
    r.dir = target - r.org;
    if (!ray_valid(r)) continue;
    const WatertightTest::Prepared p = WatertightTest::prepare(r);
    const int axis[3] = {p.kx, p.ky, p.kz};
    float pv[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) pv[k][a] = v[k][axis[a]];
    const EdgeFunctions f = WatertightTest::edge_functions(p, pv);
    AABB box;
    for (const Vec3f& q : v) box.extend(q);
    const double lane_bound = WatertightTest::prepare(r, box).lane_bound;
    const double dz = r.dir[p.kz];
    static constexpr int kEdge[3][2] = {{1, 2}, {2, 0}, {0, 1}};  // (p, q) of U, V, W
    for (int e = 0; e < 3; ++e) {
      const int a = kEdge[e][0], b = kEdge[e][1];
      Expansion q[3], pp[3];
      for (int c = 0; c < 3; ++c) {
        q[c] = exact::diff(pv[b][c], r.org[axis[c]]);
        pp[c] = exact::diff(pv[a][c], r.org[axis[c]]);
      }
      const Expansion d0(double(r.dir[axis[0]])), d1(double(r.dir[axis[1]])), d2(dz);
      const Expansion t = d0 * (q[1] * pp[2] - q[2] * pp[1]) + d1 * (q[2] * pp[0] - q[0] * pp[2]) +
                          d2 * (q[0] * pp[1] - q[1] * pp[0]);
      const Expansion err = Expansion(f.e[e]) * d2 - t;  // d_z (U_double - U)
      const Expansion room = Expansion(f.bound[e]) * Expansion(std::fabs(dz));
      ASSERT_GE((room - err).sign(), 0) << "ray " << i << " edge " << e;
      ASSERT_GE((room + err).sign(), 0) << "ray " << i << " edge " << e;
      // The lanes' one bound per ray (from the box of the tree's triangles).
      const Expansion lane_room = Expansion(lane_bound) * Expansion(std::fabs(dz));
      ASSERT_GE((lane_room - err).sign(), 0) << "ray " << i << " edge " << e;
      ASSERT_GE((lane_room + err).sign(), 0) << "ray " << i << " edge " << e;
      ++checked;
    }
  }
  EXPECT_GT(checked, 80000);
}

}  // namespace
}  // namespace hprt
