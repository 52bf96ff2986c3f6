// Procedural meshes for tests, benchmarks and scenes (`hprt generate`): closed
// sphere and torus, random soup and slivers, terrain and plane height fields,
// and midpoint subdivision of any mesh. All are deterministic for a seed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/triangle_mesh.h"

namespace hprt {

// What `hprt generate` and a scene's "generate" block ask for. `from` is the
// input mesh of `subdivide` (ignored by the other kinds); `seed` only matters
// for soup, slivers and terrain.
struct GenerateSpec {
  std::string kind;
  size_t tris = 20000;
  uint64_t seed = 1;
  std::string from;
};

// Largest --tris accepted: 200M triangles is ~3.6 GB as a mesh.
inline constexpr size_t kMaxGenerateTriangles = 200'000'000;

// Sphere: an icosahedron whose edges are split into m segments (20·m²
// triangles, 10·m²+2 shared vertices), projected onto the unit sphere. m is the
// smallest with 20·m² >= tris (1000 -> m=8, 1280; 1e6 -> m=224, 1,003,520).
// Closed, outward (counter-clockwise seen from outside) winding.
int sphere_segments(size_t tris);
TriangleMesh generate_sphere(size_t tris);

// Bumpy sphere: generate_sphere's mesh (same triangles, closed, outward) with
// each vertex moved along its direction by 24 seeded plane waves over the
// sphere (frequencies 2..40, amplitude ~ 1/frequency): radius within 1 ± 0.2,
// smooth and curved at many scales, like a scanned surface.
TriangleMesh generate_bumpy_sphere(size_t tris, uint64_t seed);

// Torus around the y axis (major radius 1, minor 0.35): a major × minor grid of
// quads, 2·major·minor triangles with minor = max(3, round(sqrt(tris/6))) and
// major = max(3, ceil(tris / (2·minor))), so at least `tris` and fewer than
// tris + 2·minor. Closed, outward winding.
TriangleMesh generate_torus(size_t tris);

// Exactly `tris` random non-degenerate triangles inside the unit cube [0,1]³:
// uniform centres, random orientation, circumradius 0.5..1 × 0.5/cbrt(tris).
TriangleMesh generate_soup(size_t tris, uint64_t seed);

// Exactly `tris` long thin triangles (length 0.05..0.3, aspect ratio 1000:1)
// in random directions inside the unit cube.
TriangleMesh generate_slivers(size_t tris, uint64_t seed);

// Height fields over [-1,1]² in the xz plane, normals facing +y, open: a g × g
// grid of quads, 2·g² triangles with g = max(1, ceil(sqrt(tris/2))).
// Terrain: seeded value noise (5 octaves, heights within about ±0.25).
// Plane: flat at y = 0.
int grid_segments(size_t tris);
TriangleMesh generate_terrain(size_t tris, uint64_t seed);
TriangleMesh generate_plane(size_t tris);

// Sliver sheet: the terrain's height field on gx × (100·gx) cells, each
// 100 times longer in x than in z, so every triangle is a 100:1 sliver; gx
// the smallest with 200·gx² >= tris. Open, normals facing +y.
inline constexpr size_t kSliverAspect = 100;
TriangleMesh generate_sliver_sheet(size_t tris, uint64_t seed);

// Midpoint subdivision: each triangle becomes 4, edge midpoints shared through
// an edge table (so a closed mesh stays closed, winding is kept); repeated
// while the count is below `tris`, so the result has at least `tris`
// triangles (the input itself when it already has). Normals are dropped.
// Throws InputError(mesh.name, ...) for an empty mesh or an index out of range.
TriangleMesh subdivide_mesh(const TriangleMesh& mesh, size_t tris);

}  // namespace hprt
