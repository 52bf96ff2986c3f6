/* hprt plugin ABI, version 1: a ray tracer built as a shared library that hprt
 * loads with `--backend plugin:PATH.so` (options after a second colon:
 * `plugin:PATH.so:key=value,...`, passed verbatim to create()). hprt then
 * traces, renders, validates (against Embree or any other backend, with its
 * exact arbiter) and benchmarks it like its built-in backends.
 *
 * Plain C, no dependencies: usable from C, C++, Rust or Zig. Version 1 never
 * changes; a later version gets its own struct and number.
 *
 * Semantics are Embree 3's, as hprt's own backends follow them:
 *  - closest hit with t in (tnear, tfar]; triangles are double-sided; primID is the
 *    triangle's index in its mesh, geomID the mesh's index in the array given
 *    to build(); u, v are the barycentrics of vertices 1 and 2 of the triangle
 *    (the hit point is (1-u-v)*v0 + u*v1 + v*v2);
 *  - a miss has t = +inf and geom_id = prim_id = 0xFFFFFFFF (u, v unused);
 *  - rays whose origin or direction has a NaN or infinite component or one of
 *    magnitude above 1.844e18 (Embree's FLT_LARGE), a zero direction,
 *    tnear < 0 or not tnear <= tfar miss (occluded = 0); tfar = +inf (most
 *    rays' own) is valid;
 *  - triangles with an index out of range, a non-finite vertex or zero area
 *    are never hit.
 *
 * Threads: hprt calls intersect() and occluded() concurrently from its own
 * threads, each call on a disjoint part of a batch (as Embree's API is
 * called), so a plugin needs no thread pool of its own; both must be safe to
 * call concurrently on one built backend. create(), build(), update() and
 * destroy() are never called concurrently with anything on the same backend.
 * A call gets 1 to 256 rays (any count, not only multiples of 16); records
 * are aligned only as their fields are (4 bytes): assume no more.
 * intersect() must write every hit record of its call (a miss too) and
 * occluded() every byte: hprt fills them with malformed values before the
 * call, so a record left as it was counts as malformed (below).
 * `threads` in create() is the thread count the user asked for (0 = every
 * hardware thread); a plugin may use it to size its own build.
 *
 * Memory: the arrays in hprt_mesh belong to hprt and stay valid from build()
 * (or update()) until the next build(), update() or destroy(); a plugin may
 * keep pointers into them instead of copying, taking them again from each
 * update(). hprt writes a deformed frame's vertices into those same arrays
 * before it calls update() (the command line's animations and the Python
 * module's update_triangles do; a C++ program's shared mesh may come with
 * new arrays instead), so a plugin must not use them between the end of a
 * query batch and update(). update() gets the same meshes as
 * the last build() (same counts and indices); when they differ, or the user
 * asked for --update rebuild, hprt calls build() instead. build() may get no
 * meshes (mesh_count 0, meshes NULL: an empty scene, whose rays all miss).
 *
 * Loading: `plugin:PATH.so[:OPTIONS]` takes PATH up to the next colon, so a
 * plugin's path cannot contain one (options may).
 *
 * Trust: hprt checks every answer. A hit with t not finite or outside
 * (tnear, tfar], on a ray that must miss, with an id out of range, or with
 * u, v outside the triangle, and an occlusion byte other than 0 or 1, is
 * malformed: `hprt validate rays` and `hprt bench frontier` count it as
 * wrong; every other command treats a malformed hit as a miss (reported
 * with t = NaN, in Python's t_hit too) and a malformed byte as occluded, and
 * warns with their count (the command's one stderr line, a Python
 * RuntimeWarning, `malformed_answers` in the JSON and info()). A plugin runs
 * inside hprt's process: a plugin that crashes or corrupts memory takes hprt
 * down with it, as any in-process plugin would.
 *
 * Errors: create(), build() and update() report failure (NULL resp. nonzero)
 * with a one-line message written into `error` (at most error_size bytes,
 * NUL-terminated); hprt prints it naming the plugin and exits with code 2. */
#ifndef HPRT_PLUGIN_H
#define HPRT_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define HPRT_PLUGIN_ABI_VERSION 1

/* One 32-byte record of hprt's .rays file format. */
typedef struct {
  float org_x, org_y, org_z, tnear, dir_x, dir_y, dir_z, tfar;
} hprt_ray;

/* One 20-byte record of hprt's .hits file format; miss: t = +inf, ids 0xFFFFFFFF. */
typedef struct {
  float t, u, v;
  uint32_t geom_id, prim_id;
} hprt_hit;

/* One triangle mesh: xyz per vertex, 3 indices per triangle. */
typedef struct {
  const float* vertices;
  const uint32_t* indices;
  uint32_t vertex_count, triangle_count;
} hprt_mesh;

/* The plugin's own state, opaque to hprt. */
typedef struct hprt_backend hprt_backend;

typedef struct {
  uint32_t abi_version; /* HPRT_PLUGIN_ABI_VERSION */
  const char* name;     /* shown in hprt's tables, e.g. "bruteforce" */
  /* options: the text after the second colon of the backend spec ("" when
   * none). NULL + message on failure. */
  hprt_backend* (*create)(const char* options, int threads, char* error, size_t error_size);
  /* Builds over the meshes (geomID = index). 0 = ok. */
  int (*build)(hprt_backend*, const hprt_mesh* meshes, uint32_t mesh_count, char* error,
               size_t error_size);
  /* The same meshes with moved vertices (same counts and indices). May be
   * NULL: hprt calls build() again. 0 = ok. */
  int (*update)(hprt_backend*, const hprt_mesh* meshes, uint32_t mesh_count, char* error,
                size_t error_size);
  void (*intersect)(const hprt_backend*, const hprt_ray* rays, hprt_hit* hits, size_t count);
  /* 1 = occluded: some hit with t in (tnear, tfar]. */
  void (*occluded)(const hprt_backend*, const hprt_ray* rays, uint8_t* occluded, size_t count);
  void (*destroy)(hprt_backend*);
} hprt_plugin_v1;

/* The one exported symbol. Returns a pointer to a static table. */
#if defined(_WIN32)
#define HPRT_PLUGIN_EXPORT __declspec(dllexport)
#else
#define HPRT_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif
HPRT_PLUGIN_EXPORT const hprt_plugin_v1* hprt_plugin_entry(void);

#ifdef __cplusplus
}
#endif

#endif /* HPRT_PLUGIN_H */
