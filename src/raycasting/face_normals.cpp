#include "raycasting/face_normals.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace hprt::raycasting {
namespace {

// (b - a) x (c - a), unit length (computed in double); zero when degenerate.
void unit_normal(const float* a, const float* b, const float* c, float* n) {
  const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
  const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
  const double x = e1[1] * e2[2] - e1[2] * e2[1];
  const double y = e1[2] * e2[0] - e1[0] * e2[2];
  const double z = e1[0] * e2[1] - e1[1] * e2[0];
  const double len = std::sqrt(x * x + y * y + z * z);
  n[0] = n[1] = n[2] = 0.0f;
  if (len > 0.0) n[0] = float(x / len), n[1] = float(y / len), n[2] = float(z / len);
}

}  // namespace

FaceNormals::FaceNormals(const api::Scene& scene) {
  for (uint32_t g = 0; g < scene.mesh_count(); ++g) {
    first_.push_back(triangles_);
    triangles_ += scene.indices(g).size() / 3;
  }
  normals_ = std::make_unique_for_overwrite<float[]>(3 * triangles_);
  for (uint32_t g = 0; g < scene.mesh_count(); ++g) {
    const float* v = scene.vertices(g).data();
    const uint32_t* idx = scene.indices(g).data();
    float* out = normals_.get() + 3 * first_[g];
    const auto range = [&](const tbb::blocked_range<size_t>& r) {
      for (size_t t = r.begin(); t != r.end(); ++t)
        unit_normal(v + 3 * size_t(idx[3 * t]), v + 3 * size_t(idx[3 * t + 1]),
                    v + 3 * size_t(idx[3 * t + 2]), out + 3 * t);
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, scene.indices(g).size() / 3, 16384), range);
  }
}

}  // namespace hprt::raycasting
