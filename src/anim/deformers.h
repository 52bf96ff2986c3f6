// Deformers (docs/ARCHITECTURE.md "An animation frame"): pure functions of a rest
// pose, a DeformerSpec and the time t = frame / fps. Each runs in parallel
// (tbb::parallel_for, in the caller's task arena) and allocates nothing; input
// and output may be the same buffer, so a mesh's deformers chain in place.
//
// With a = spec.axis, b = (a + 2) % 3, c = (a + 1) % 3, the rest bounds
// [lo, hi], their centre m, L = hi_a - lo_a and h = (p_a - lo_a) / L (0 if L = 0):
//  twist:   rotate p (right-handed) about the line through m along axis a by
//           θ = radians(angle_deg)·t·h (the top end has turned angle_deg after 1 s).
//  bend:    bend the mesh in the (a, b) plane into a circular arc of total angle
//           θ = radians(angle_deg)·t: with k = θ / L, s = p_a - lo_a, d = p_b - m_b,
//           φ = k·s: p_a' = lo_a + sin(φ)/k - d·sin(φ), p_b' = m_b + 2·sin²(φ/2)/k + d·cos(φ).
//  wave:    travelling sine along axis b displacing along axis a:
//           p_a' = p_a + amplitude·sin(2π·(p_b - lo_b - speed·t) / wavelength).
//  pulse:   breathing scale about the rest centroid g (mean of the vertices):
//           p' = g + (p - g)·(1 + amplitude·sin(2π·speed·t)), computed as
//           p + (p - g)·amplitude·sin(2π·speed·t) (exactly p at t = 0).
//  explode: triangle i (vertices 3i, 3i+1, 3i+2 of an unwelded mesh) moves
//           rigidly along its unit face normal n_i (of the input positions) by
//           amplitude·speed·t·f_i, f_i in [0.5, 1.5) a fixed hash of i.
#pragma once

#include <span>

#include "core/aabb.h"
#include "core/animation.h"
#include "core/triangle_mesh.h"
#include "core/vec.h"

namespace hprt {

// What the deformers need to know about the rest pose, computed once.
struct RestPose {
  AABB bounds;     // of the finite rest positions
  Vec3f centroid;  // mean of the rest positions (pulse)
};
RestPose measure_rest_pose(std::span<const Vec3f> positions);

// out[i] = D(in[i]) (explode: per triangle). `in` and `out` have the same size
// and may alias. Throws InputError for an unknown kind, or for explode when the
// size is not a multiple of 3.
void apply_deformer(const DeformerSpec& spec, const RestPose& rest, float t,
                    std::span<const Vec3f> in, std::span<Vec3f> out);

// The explode scatter factor f_i in [0.5, 1.5) of triangle i.
float explode_factor(size_t triangle);

// Gives each triangle its own three vertices (3i, 3i+1, 3i+2, normals copied),
// so triangles can move apart; triangle order and winding are kept.
void unweld(TriangleMesh& mesh);
bool is_unwelded(const TriangleMesh& mesh);

}  // namespace hprt
