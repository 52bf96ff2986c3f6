// Every hit along each ray of a batch (the `all` query): ray i's hits are
// hits[offsets[i] .. offsets[i + 1]), in order of t, then geomID, then primID;
// truncated[i] = 1 when the ray had more than the query's bound and only the
// nearest were kept.
#pragma once

#include <cstdint>
#include <vector>

#include "core/hit.h"

namespace hprt {

struct HitLists {
  std::vector<uint64_t> offsets;  // rays + 1
  std::vector<Hit> hits;
  std::vector<uint8_t> truncated;  // per ray

  size_t rays() const { return truncated.size(); }
  size_t count(size_t ray) const { return size_t(offsets[ray + 1] - offsets[ray]); }
  const Hit* begin(size_t ray) const { return hits.data() + offsets[ray]; }
};

// The order of an `all` list: t, then geomID, then primID.
inline bool hit_list_before(const Hit& a, const Hit& b) {
  if (a.t != b.t) return a.t < b.t;
  if (a.geom_id != b.geom_id) return a.geom_id < b.geom_id;
  return a.prim_id < b.prim_id;
}

}  // namespace hprt
