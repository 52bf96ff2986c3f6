// Embree as the reference in tests of ray sets: a built Embree intersector,
// closest hits of a batch, and bit-for-bit equality of two ray sets.
#pragma once

#include <cstring>
#include <memory>
#include <vector>

#include "backends/embree_backend.h"
#include "core/hit.h"
#include "core/ray.h"
#include "core/scene.h"

namespace hprt::test {

inline std::unique_ptr<Intersector> embree_over(const Scene& s, bool robust = false) {
  BackendOptions o;
  o.backend = "embree";
  o.embree_robust = robust;
  auto b = make_embree_intersector(o);
  b->build(s);
  return b;
}

inline std::vector<Hit> closest_hits(const Intersector& b, const std::vector<Ray>& rays) {
  std::vector<Hit> hits(rays.size());
  b.intersect(rays, hits);
  return hits;
}

inline bool same_bits(const std::vector<Ray>& a, const std::vector<Ray>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Ray)) == 0;
}

}  // namespace hprt::test
