// Exact ray/triangle arbitration. With A, B, C = v0, v1, v2 minus the ray
// origin and d the direction, the Plücker edge functions U = d·(B×C),
// V = d·(C×A), W = d·(A×B) are the unnormalised barycentrics of v0, v1, v2;
// D = U+V+W = d·n and the line crosses the closed triangle iff D != 0 and no
// two of U, V, W have opposite signs. t = det[A,B,C] / D. All of these are
// polynomials in the float inputs, evaluated exactly as expansions.
#include "validators/arbiter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "validators/exact_expansion.h"

namespace hprt {
namespace {

using exact::Expansion;

struct EVec {
  Expansion x, y, z;
};

EVec sub(const Vec3f& a, const Vec3f& b) {
  return {exact::diff(a.x, b.x), exact::diff(a.y, b.y), exact::diff(a.z, b.z)};
}
EVec cross(const EVec& a, const EVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Expansion dot(const EVec& a, const EVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
EVec of(const Vec3f& v) { return {Expansion(v.x), Expansion(v.y), Expansion(v.z)}; }

// t = num / den exactly, for candidates that are not parallel to the ray.
struct ExactT {
  Expansion num, den;
};

constexpr double kInf = std::numeric_limits<double>::infinity();

double max_abs(const Vec3f& v) {
  return std::max({std::fabs(double(v.x)), std::fabs(double(v.y)), std::fabs(double(v.z))});
}

// Signed distance from the ray's line to one edge line: the edge function
// (oriented so that inside is positive) over |d × edge|.
double edge_distance(const Expansion& f, int orient, const Vec3d& d, const Vec3d& edge) {
  const double s = f.sign() * orient;
  const double len = length(hprt::cross(d, edge));
  if (len == 0.0) return s > 0 ? kInf : (s < 0 ? -kInf : 0.0);
  return orient * f.estimate() / len;
}

// Coordinates of the vertices in an orthonormal basis (e1, e2) of the plane
// perpendicular to the ray, relative to its origin.
void project_along_ray(const Ray& ray, const std::array<Vec3f, 3>& v, double (&out)[3][2]) {
  const Vec3d d = normalize(Vec3d(ray.dir));
  const Vec3d helper = std::fabs(d.x) < 0.5 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
  const Vec3d e1 = normalize(hprt::cross(d, helper));
  const Vec3d e2 = hprt::cross(d, e1);
  for (int i = 0; i < 3; ++i) {
    const Vec3d q = Vec3d(v[i]) - Vec3d(ray.org);
    out[i][0] = hprt::dot(q, e1);
    out[i][1] = hprt::dot(q, e2);
  }
}

CandidateResult test_exact(const Ray& ray, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2,
                           ExactT* exact_t) {
  CandidateResult r;
  r.t = std::numeric_limits<double>::quiet_NaN();
  r.margin = -kInf;
  r.scale = std::max({max_abs(ray.org), max_abs(v0), max_abs(v1), max_abs(v2)});
  if (!is_finite(v0) || !is_finite(v1) || !is_finite(v2)) return r;
  const EVec n = cross(sub(v1, v0), sub(v2, v0));
  if (n.x.sign() == 0 && n.y.sign() == 0 && n.z.sign() == 0) return r;
  r.valid = true;
  if (!arbiter_ray_valid(ray)) return r;

  const EVec a = sub(v0, ray.org), b = sub(v1, ray.org), c = sub(v2, ray.org);
  const EVec d = of(ray.dir);
  const Expansion u = dot(d, cross(b, c));
  const Expansion v = dot(d, cross(c, a));
  const Expansion w = dot(d, cross(a, b));
  const Expansion den = u + v + w;
  const int sd = den.sign();
  if (sd == 0) return r;  // parallel to the plane: never a hit (as in Embree)

  const Vec3d dd(ray.dir);
  project_along_ray(ray, {v0, v1, v2}, r.proj);
  r.t_per_distance =
      length(hprt::cross(Vec3d(v1) - Vec3d(v0), Vec3d(v2) - Vec3d(v0))) / std::fabs(den.estimate());
  const double mu = edge_distance(u, sd, dd, Vec3d(v2) - Vec3d(v1));
  const double mv = edge_distance(v, sd, dd, Vec3d(v0) - Vec3d(v2));
  const double mw = edge_distance(w, sd, dd, Vec3d(v1) - Vec3d(v0));
  r.margin = std::min({mu, mv, mw});

  const Expansion num = dot(a, cross(b, c));
  r.t = num.estimate() / den.estimate();
  if (exact_t) *exact_t = {num, den};

  const int su = u.sign() * sd, sv = v.sign() * sd, sw = w.sign() * sd;
  r.inside = su >= 0 && sv >= 0 && sw >= 0;
  if (!r.inside) return r;
  r.zero_edges = (su == 0) + (sv == 0) + (sw == 0);
  // tnear < num/den <= tfar, multiplied through by den (sign sd).
  const bool after_near = (num - den * Expansion(double(ray.tnear))).sign() * sd > 0;
  const bool before_far =
      std::isinf(ray.tfar) || (den * Expansion(double(ray.tfar)) - num).sign() * sd >= 0;
  r.hit = after_near && before_far;
  return r;
}

bool triangle_vertices(const Scene& scene, PrimRef p, Vec3f& v0, Vec3f& v1, Vec3f& v2) {
  if (p.geom_id >= scene.meshes.size()) return false;
  const TriangleMesh& m = scene.meshes[p.geom_id];
  if (p.prim_id >= m.triangles.size()) return false;
  const Vec3u& t = m.triangles[p.prim_id];
  const size_t nv = m.positions.size();
  if (t[0] >= nv || t[1] >= nv || t[2] >= nv) return false;
  v0 = m.positions[t[0]];
  v1 = m.positions[t[1]];
  v2 = m.positions[t[2]];
  return true;
}

CandidateResult test_ref(const Scene& scene, const Ray& ray, PrimRef p, ExactT* exact_t) {
  Vec3f v0, v1, v2;
  CandidateResult r;
  if (triangle_vertices(scene, p, v0, v1, v2)) r = test_exact(ray, v0, v1, v2, exact_t);
  r.prim = p;
  return r;
}

int compare_exact(const ExactT& a, const ExactT& b) {
  const int s = (a.num * b.den - b.num * a.den).sign();
  return s * a.den.sign() * b.den.sign();
}

}  // namespace

bool arbiter_ray_valid(const Ray& ray) { return ray_valid(ray); }

CandidateResult arbitrate_triangle(const Ray& ray, const Vec3f& v0, const Vec3f& v1,
                                   const Vec3f& v2) {
  return test_exact(ray, v0, v1, v2, nullptr);
}

ArbiterAnswer arbitrate(const Scene& scene, const Ray& ray, std::span<const PrimRef> candidates) {
  ArbiterAnswer ans;
  ans.candidates.reserve(candidates.size());
  ExactT best;
  for (const PrimRef& p : candidates) {
    ExactT et;
    ans.candidates.push_back(test_ref(scene, ray, p, &et));
    const CandidateResult& c = ans.candidates.back();
    if (!c.hit) continue;
    ++ans.hits;
    if (!ans.hit) {
      ans.hit = true;
      ans.prim = p;
      ans.t = c.t;
      best = std::move(et);
      continue;
    }
    if (p == ans.prim) continue;  // the same triangle listed twice
    const int cmp = compare_exact(et, best);
    if (cmp < 0) {
      ans.prim = p;
      ans.t = c.t;
      ans.tie = false;
      best = std::move(et);
    } else if (cmp == 0) {
      ans.tie = true;
    }
  }
  return ans;
}

std::vector<PrimRef> line_candidates(const Scene& scene, const Ray& ray, double near_rel) {
  std::vector<PrimRef> out;
  if (!arbiter_ray_valid(ray)) return out;
  const Vec3d o(ray.org), d(ray.dir);
  const Vec3d ad(std::fabs(d.x), std::fabs(d.y), std::fabs(d.z));
  // Edge function f = d·(P×Q) in double from P, Q = vertex - origin (each
  // rounded once): its error is below ~10 ulps of the permanent
  // |d|·(|P|×|Q|); 1e-13 of it (~900 ulps) plus an absolute floor is safe.
  // f / |d × (Q - P)| is the signed distance from the line to the edge, so
  // widening the bound by near · |d × (Q - P)| keeps near misses.
  auto edge = [&](const Vec3d& p, const Vec3d& q, double near, double& f, double& bound) {
    f = dot(d, hprt::cross(p, q));
    const Vec3d ap(std::fabs(p.x), std::fabs(p.y), std::fabs(p.z));
    const Vec3d aq(std::fabs(q.x), std::fabs(q.y), std::fabs(q.z));
    const Vec3d perm(ap.y * aq.z + ap.z * aq.y, ap.z * aq.x + ap.x * aq.z,
                     ap.x * aq.y + ap.y * aq.x);
    bound = 1e-13 * dot(ad, perm) + 1e-300 + near * length(hprt::cross(d, q - p));
  };
  const double org_scale = max_abs(ray.org);
  for (uint32_t g = 0; g < scene.meshes.size(); ++g) {
    const TriangleMesh& m = scene.meshes[g];
    const size_t nv = m.positions.size();
    for (uint32_t i = 0; i < m.triangles.size(); ++i) {
      const Vec3u& t = m.triangles[i];
      if (t[0] >= nv || t[1] >= nv || t[2] >= nv) continue;
      const Vec3f &v0 = m.positions[t[0]], &v1 = m.positions[t[1]], &v2 = m.positions[t[2]];
      if (!is_finite(v0) || !is_finite(v1) || !is_finite(v2)) continue;
      const Vec3d a = Vec3d(v0) - o, b = Vec3d(v1) - o, c = Vec3d(v2) - o;
      const double near =
          near_rel > 0 ? near_rel * std::max({org_scale, max_abs(v0), max_abs(v1), max_abs(v2)})
                       : 0.0;
      double fu, bu, fv, bv, fw, bw;
      edge(b, c, near, fu, bu);
      edge(c, a, near, fv, bv);
      edge(a, b, near, fw, bw);
      const bool pos = fu > bu || fv > bv || fw > bw;
      const bool neg = fu < -bu || fv < -bv || fw < -bw;
      if (pos && neg) continue;  // proven: the line passes outside
      out.push_back({g, i});
    }
  }
  return out;
}

ArbiterAnswer arbitrate_brute_force(const Scene& scene, const Ray& ray, double near_rel) {
  const std::vector<PrimRef> c = line_candidates(scene, ray, near_rel);
  return arbitrate(scene, ray, c);
}

int compare_t(const Scene& scene, const Ray& ray, PrimRef a, PrimRef b) {
  ExactT ta, tb;
  const CandidateResult ra = test_ref(scene, ray, a, &ta);
  const CandidateResult rb = test_ref(scene, ray, b, &tb);
  if (ta.den.sign() == 0 || tb.den.sign() == 0) return 0;
  (void)ra;
  (void)rb;
  return compare_exact(ta, tb);
}

}  // namespace hprt
