// The exact point predicates (core/exact_predicates.h) against integer
// arithmetic: coordinates are multiples of 2^-8 below 2^22 in magnitude, so
// every float input is exact and every determinant fits in __int128. The
// sets are built to be degenerate (coplanar points, points on edges and
// vertices) or one lattice step away from it, where the double filter cannot
// decide and the expansion path must.
#include <gtest/gtest.h>

#include <cmath>

#include "core/exact_predicates.h"
#include "core/splitmix64.h"

namespace hprt {
namespace {

__extension__ typedef __int128 I;
struct P {
  int64_t x, y, z;  // units of 2^-8
};
Vec3f to_float(const P& p) {
  return {std::ldexp(float(p.x), -8), std::ldexp(float(p.y), -8), std::ldexp(float(p.z), -8)};
}
I det3(const P& r0, const P& r1, const P& r2) {
  return I(r0.x) * (I(r1.y) * r2.z - I(r1.z) * r2.y) - I(r0.y) * (I(r1.x) * r2.z - I(r1.z) * r2.x) +
         I(r0.z) * (I(r1.x) * r2.y - I(r1.y) * r2.x);
}
P minus(const P& a, const P& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
int sign(I v) { return (v > 0) - (v < 0); }

class Lattice {
 public:
  explicit Lattice(uint64_t seed) : rng_(seed) {}
  int64_t coord(int64_t range) { return int64_t(rng_.below(size_t(2 * range + 1))) - range; }
  P point(int64_t range) { return {coord(range), coord(range), coord(range)}; }
  SplitMix64& rng() { return rng_; }

 private:
  SplitMix64 rng_;
};

TEST(ExactPredicates, Orient3dSignsMatchIntegerArithmetic) {
  Lattice lat(3);
  int zero = 0, tiny = 0;
  for (int i = 0; i < 20000; ++i) {
    // Large offsets, small triangles: the double filter is tight there.
    const int64_t far = int64_t(1) << (10 + lat.rng().below(11));
    const P base = lat.point(far);
    const auto near = [&] {
      const P d = lat.point(64);
      return P{base.x + d.x, base.y + d.y, base.z + d.z};
    };
    const P a = near(), b = near(), c = near();
    // p coplanar with abc (an integer combination), or one unit off it.
    const int64_t s = lat.coord(3), t = lat.coord(3);
    P p{a.x + s * (b.x - a.x) + t * (c.x - a.x), a.y + s * (b.y - a.y) + t * (c.y - a.y),
        a.z + s * (b.z - a.z) + t * (c.z - a.z)};
    const int nudge = int(lat.rng().below(3));
    if (nudge == 1) p.x += 1;
    if (nudge == 2) p.z -= 1;
    const int expected = sign(det3(minus(b, a), minus(c, a), minus(p, a)));
    zero += expected == 0;
    tiny += expected != 0;
    ASSERT_EQ(exact::orient3d(to_float(a), to_float(b), to_float(c), to_float(p)), expected) << i;
    const P d = lat.point(5);
    const P dir = nudge == 0 ? minus(minus(p, a), P{0, 0, 0}) : d;
    // plane_direction with an integer direction (exact as a float too).
    const Vec3f df{float(dir.x), float(dir.y), float(dir.z)};
    const int dexp = sign(det3(minus(b, a), minus(c, a), dir));  // scaled by 2^8: same sign
    ASSERT_EQ(exact::plane_direction(to_float(a), to_float(b), to_float(c), df), dexp) << i;
  }
  EXPECT_GT(zero, 5000);
  EXPECT_GT(tiny, 5000);
}

TEST(ExactPredicates, OnTriangleExactlyOnVerticesEdgesAndInterior) {
  Lattice lat(5);
  int on = 0, off = 0;
  for (int i = 0; i < 20000; ++i) {
    const int64_t far = int64_t(1) << (4 + lat.rng().below(16));
    const P base = lat.point(far);
    // A triangle with vertices a, a + 4e1, a + 4e2 so that edge midpoints and
    // the points (i e1 + j e2) for i, j >= 0, i + j <= 4 are lattice points.
    const P e1 = lat.point(40), e2 = lat.point(40);
    const P a = base;
    const P b{a.x + 4 * e1.x, a.y + 4 * e1.y, a.z + 4 * e1.z};
    const P c{a.x + 4 * e2.x, a.y + 4 * e2.y, a.z + 4 * e2.z};
    const I n[3] = {I(e1.y) * e2.z - I(e1.z) * e2.y, I(e1.z) * e2.x - I(e1.x) * e2.z,
                    I(e1.x) * e2.y - I(e1.y) * e2.x};
    if (n[0] == 0 && n[1] == 0 && n[2] == 0) {
      EXPECT_FALSE(exact::on_triangle(to_float(a), to_float(b), to_float(c), to_float(a)));
      continue;
    }
    const int64_t s = lat.coord(5), t = lat.coord(5);  // -5..5: inside when s, t >= 0, s + t <= 4
    P p{a.x + s * e1.x + t * e2.x, a.y + s * e1.y + t * e2.y, a.z + s * e1.z + t * e2.z};
    bool expected = s >= 0 && t >= 0 && s + t <= 4;
    if (lat.rng().coin()) {
      // One lattice step off: off the plane unless the step lies in it.
      const int axis = int(lat.rng().below(3));
      (axis == 0 ? p.x : axis == 1 ? p.y : p.z) += 1;
      if (n[axis] != 0)
        expected = false;
      else
        continue;  // the step stays in the plane: containment unclear, skip
    }
    on += expected;
    off += !expected;
    ASSERT_EQ(exact::on_triangle(to_float(a), to_float(b), to_float(c), to_float(p)), expected)
        << i << " s=" << s << " t=" << t;
  }
  EXPECT_GT(on, 1000);
  EXPECT_GT(off, 2000);
}

}  // namespace
}  // namespace hprt
