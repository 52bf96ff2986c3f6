// A scene mesh's placement: scale, then rotation about X, then Y, then Z (in
// degrees, right-handed), then translation: p' = T + Rz·Ry·Rx·(S·p).
#pragma once

#include "core/triangle_mesh.h"
#include "core/vec.h"

namespace hprt {

struct MeshTransform {
  Vec3f scale{1.0f, 1.0f, 1.0f};
  Vec3f rotate_deg{0.0f, 0.0f, 0.0f};
  Vec3f translate{0.0f, 0.0f, 0.0f};
  bool identity() const {
    return scale == Vec3f(1.0f) && rotate_deg == Vec3f(0.0f) && translate == Vec3f(0.0f);
  }
};

// Transforms positions (computed in double) and normals (inverse transpose,
// R·S⁻¹, renormalised). Scale components must be non-zero.
void apply_transform(TriangleMesh& mesh, const MeshTransform& t);

}  // namespace hprt
