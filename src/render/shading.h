// Local shading of the Whitted integrator: ambient, Lambert diffuse and
// Blinn-Phong specular per light (Blinn 1977), mirror reflection direction.
// Point lights have no distance falloff (classic Whitted 1980): a light's
// intensity is the irradiance it gives a surface facing it at any distance.
#pragma once

#include <cmath>
#include <limits>

#include "core/light.h"
#include "core/material.h"
#include "core/vec.h"

namespace hprt {

// ambient * diffuse: the whole colour of a point no light reaches.
inline Vec3f ambient_term(const Vec3f& ambient, const Material& m) { return ambient * m.diffuse; }

// One light's contribution: (kd max(0, n.l) + ks max(0, n.h)^shininess) * I.
// n: unit shading normal, l: unit direction to the light, v: unit direction
// to the viewer. Zero when the light is behind the surface (n.l <= 0).
inline Vec3f direct_term(const Material& m, const Vec3f& n, const Vec3f& l, const Vec3f& v,
                         const Vec3f& intensity) {
  const float n_dot_l = dot(n, l);
  if (!(n_dot_l > 0.0f)) return Vec3f(0.0f);
  Vec3f c = m.diffuse * n_dot_l;
  if (m.specular.x > 0.0f || m.specular.y > 0.0f || m.specular.z > 0.0f) {
    const Vec3f h_sum = l + v;
    const float h_len = length(h_sum);
    if (h_len > 0.0f) {
      const float n_dot_h = dot(n, h_sum) / h_len;
      if (n_dot_h > 0.0f) c += m.specular * std::pow(n_dot_h, m.shininess);
    }
  }
  return c * intensity;
}

// Mirror direction of d about the unit normal n.
inline Vec3f reflect(const Vec3f& d, const Vec3f& n) { return d - n * (2.0f * dot(d, n)); }

// Where a shadow ray from `origin` goes for `light`: `dir` is unnormalised and
// [0, tfar] covers exactly the segment to the light. A point light is a point,
// not geometry, so tfar = 1 (the light's position) cannot hit the light
// itself; a directional light is at infinity (tfar = inf).
struct ShadowSegment {
  Vec3f dir;       // for the shadow ray
  Vec3f to_light;  // unit direction to the light, for shading
  float tfar;
};

inline ShadowSegment shadow_segment(const Light& light, const Vec3f& origin) {
  if (light.type == LightType::kDirectional) {
    const Vec3f l = normalize(-light.direction);
    return {l, l, std::numeric_limits<float>::infinity()};
  }
  const Vec3f d = light.position - origin;
  return {d, normalize(d), 1.0f};
}

}  // namespace hprt
