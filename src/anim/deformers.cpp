// The five deformers (formulas in deformers.h), the rest-pose measurements
// they use, and unwelding for explode.
#include "anim/deformers.h"
#include "core/splitmix64.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.h"

namespace hprt {
namespace {

constexpr float kTwoPi = 2.0f * std::numbers::pi_v<float>;
constexpr float kDegToRad = std::numbers::pi_v<float> / 180.0f;

// Grain of the parallel loops: enough work per task to hide scheduling.
constexpr size_t kGrain = 4096;

template <typename F>
void for_each_index(size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) f(i);
                    });
}

struct AxisFrame {
  int a, b, c;  // deformation axis and the two others (see deformers.h)
  float lo_a, length_a;
};

AxisFrame axis_frame(const DeformerSpec& spec, const RestPose& rest) {
  AxisFrame f;
  f.a = spec.axis;
  f.b = (spec.axis + 2) % 3;
  f.c = (spec.axis + 1) % 3;
  f.lo_a = rest.bounds.empty() ? 0.0f : rest.bounds.min[f.a];
  f.length_a = rest.bounds.empty() ? 0.0f : rest.bounds.max[f.a] - rest.bounds.min[f.a];
  return f;
}

float height_fraction(const AxisFrame& f, float p_a) {
  return f.length_a > 0.0f ? (p_a - f.lo_a) / f.length_a : 0.0f;
}

void twist(const DeformerSpec& spec, const RestPose& rest, float t, std::span<const Vec3f> in,
           std::span<Vec3f> out) {
  const AxisFrame f = axis_frame(spec, rest);
  const Vec3f m = rest.bounds.empty() ? Vec3f(0.0f) : rest.bounds.center();
  const float theta_top = spec.angle_deg * kDegToRad * t;
  for_each_index(in.size(), [&](size_t i) {
    const Vec3f p = in[i];
    const float theta = theta_top * height_fraction(f, p[f.a]);
    const float cs = std::cos(theta), sn = std::sin(theta);
    const float u = p[f.c] - m[f.c], v = p[f.b] - m[f.b];  // right-handed about axis a
    Vec3f q = p;
    q[f.c] = m[f.c] + cs * u - sn * v;
    q[f.b] = m[f.b] + sn * u + cs * v;
    out[i] = q;
  });
}

void bend(const DeformerSpec& spec, const RestPose& rest, float t, std::span<const Vec3f> in,
          std::span<Vec3f> out) {
  const AxisFrame f = axis_frame(spec, rest);
  const float theta = spec.angle_deg * kDegToRad * t;
  const float k = f.length_a > 0.0f ? theta / f.length_a : 0.0f;
  if (k == 0.0f || !std::isfinite(k)) {
    if (in.data() != out.data()) for_each_index(in.size(), [&](size_t i) { out[i] = in[i]; });
    return;
  }
  const float m_b = rest.bounds.center()[f.b];
  for_each_index(in.size(), [&](size_t i) {
    const Vec3f p = in[i];
    const float s = p[f.a] - f.lo_a, d = p[f.b] - m_b;
    const float phi = k * s;
    const float sn = std::sin(phi), cs = std::cos(phi), half = std::sin(0.5f * phi);
    Vec3f q = p;
    q[f.a] = f.lo_a + sn / k - d * sn;
    q[f.b] = m_b + 2.0f * half * half / k + d * cs;
    out[i] = q;
  });
}

void wave(const DeformerSpec& spec, const RestPose& rest, float t, std::span<const Vec3f> in,
          std::span<Vec3f> out) {
  const AxisFrame f = axis_frame(spec, rest);
  const float lo_b = rest.bounds.empty() ? 0.0f : rest.bounds.min[f.b];
  const float shift = spec.speed * t;
  const float k = kTwoPi / spec.wavelength;
  for_each_index(in.size(), [&](size_t i) {
    Vec3f q = in[i];
    q[f.a] += spec.amplitude * std::sin(k * (q[f.b] - lo_b - shift));
    out[i] = q;
  });
}

void pulse(const DeformerSpec& spec, const RestPose& rest, float t, std::span<const Vec3f> in,
           std::span<Vec3f> out) {
  const Vec3f g = rest.centroid;
  const float grow = spec.amplitude * std::sin(kTwoPi * spec.speed * t);  // scale - 1
  for_each_index(in.size(), [&](size_t i) { out[i] = in[i] + (in[i] - g) * grow; });
}

void explode(const DeformerSpec& spec, float t, std::span<const Vec3f> in, std::span<Vec3f> out) {
  if (in.size() % 3 != 0)
    throw InputError("explode", "needs an unwelded mesh (3 vertices per triangle), got " +
                                    std::to_string(in.size()) + " vertices");
  const float distance = spec.amplitude * spec.speed * t;
  for_each_index(in.size() / 3, [&](size_t tri) {
    const Vec3f a = in[3 * tri], b = in[3 * tri + 1], c = in[3 * tri + 2];
    const Vec3f n = cross(b - a, c - a);
    const float len = length(n);
    const Vec3f offset =
        len > 0.0f && std::isfinite(len) ? n * (distance * explode_factor(tri) / len) : Vec3f(0.0f);
    out[3 * tri] = a + offset;
    out[3 * tri + 1] = b + offset;
    out[3 * tri + 2] = c + offset;
  });
}

}  // namespace

RestPose measure_rest_pose(std::span<const Vec3f> positions) {
  RestPose rest;
  Vec3d sum(0.0);
  size_t n = 0;
  for (const Vec3f& p : positions) {
    if (!is_finite(p)) continue;
    rest.bounds.extend(p);
    sum += Vec3d(p);
    ++n;
  }
  rest.centroid = n > 0 ? Vec3f(sum / double(n)) : Vec3f(0.0f);
  return rest;
}

float explode_factor(size_t triangle) {
  const uint64_t z = splitmix64(uint64_t(triangle));
  return 0.5f + float(z >> 40) * (1.0f / 16777216.0f);
}

void apply_deformer(const DeformerSpec& spec, const RestPose& rest, float t,
                    std::span<const Vec3f> in, std::span<Vec3f> out) {
  if (in.size() != out.size()) throw InputError(spec.kind, "input and output vertex counts differ");
  if (spec.kind == "twist") return twist(spec, rest, t, in, out);
  if (spec.kind == "bend") return bend(spec, rest, t, in, out);
  if (spec.kind == "wave") return wave(spec, rest, t, in, out);
  if (spec.kind == "pulse") return pulse(spec, rest, t, in, out);
  if (spec.kind == "explode") return explode(spec, t, in, out);
  throw InputError("deformer",
                   "unknown kind '" + spec.kind + "' (twist, bend, wave, pulse, explode)");
}

void unweld(TriangleMesh& mesh) {
  const size_t n = mesh.triangles.size();
  const bool has_normals = mesh.normals.size() == mesh.positions.size();
  std::vector<Vec3f> positions(3 * n), normals(has_normals ? 3 * n : 0);
  std::vector<Vec3u> triangles(n);
  const size_t nv = mesh.positions.size();
  const Vec3f bad(std::numeric_limits<float>::quiet_NaN());
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[i][k];
      // An out-of-range index stays a triangle that can never hit (NaN vertex).
      positions[3 * i + k] = v < nv ? mesh.positions[v] : bad;
      if (has_normals) normals[3 * i + k] = v < nv ? mesh.normals[v] : Vec3f(0.0f, 0.0f, 1.0f);
      triangles[i][k] = uint32_t(3 * i + k);
    }
  }
  mesh.positions = std::move(positions);
  mesh.normals = std::move(normals);
  mesh.triangles = std::move(triangles);
  mesh.pad_for_embree();
}

bool is_unwelded(const TriangleMesh& mesh) {
  if (mesh.positions.size() != 3 * mesh.triangles.size()) return false;
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (mesh.triangles[i][k] != 3 * i + k) return false;
  return true;
}

}  // namespace hprt
