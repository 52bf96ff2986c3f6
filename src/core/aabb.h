// Axis-aligned bounding box. An empty box has min = +inf, max = -inf, so
// extending it by anything gives that thing and its surface area is 0.
#pragma once

#include <limits>

#include "core/vec.h"

namespace hprt {

struct AABB {
  Vec3f min{std::numeric_limits<float>::infinity()};
  Vec3f max{-std::numeric_limits<float>::infinity()};

  constexpr AABB() = default;
  constexpr AABB(const Vec3f& lo, const Vec3f& hi) : min(lo), max(hi) {}

  constexpr void extend(const Vec3f& p) {
    min = hprt::min(min, p);
    max = hprt::max(max, p);
  }
  constexpr void extend(const AABB& b) {
    min = hprt::min(min, b.min);
    max = hprt::max(max, b.max);
  }
  constexpr bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  constexpr Vec3f diagonal() const { return max - min; }
  constexpr Vec3f center() const { return (min + max) * 0.5f; }
  constexpr float half_area() const {
    if (empty()) return 0.0f;
    Vec3f d = diagonal();
    return d.x * d.y + d.y * d.z + d.z * d.x;
  }
  constexpr float surface_area() const { return 2.0f * half_area(); }
  constexpr bool contains(const AABB& b) const {
    return b.empty() || (min.x <= b.min.x && min.y <= b.min.y && min.z <= b.min.z &&
                         max.x >= b.max.x && max.y >= b.max.y && max.z >= b.max.z);
  }
  constexpr bool contains(const Vec3f& p) const {
    return min.x <= p.x && min.y <= p.y && min.z <= p.z && max.x >= p.x && max.y >= p.y &&
           max.z >= p.z;
  }
  constexpr bool operator==(const AABB&) const = default;
};

}  // namespace hprt
