/* Test plugins for hprt's plugin loader and its error handling. This one file
 * is built into one MODULE library per variant, selected by exactly one
 * define:
 *   HPRT_TEST_PLUGIN_GOOD           correct brute force (the only one with update())
 *   HPRT_TEST_PLUGIN_BAD_ABI        abi_version = 2
 *   HPRT_TEST_PLUGIN_NULL_INTERSECT intersect = NULL
 *   HPRT_TEST_PLUGIN_NO_ENTRY       exports no hprt_plugin_entry
 *   HPRT_TEST_PLUGIN_ENTRY_NULL     hprt_plugin_entry() returns NULL
 *   HPRT_TEST_PLUGIN_CREATE_FAILS   create() fails
 *   HPRT_TEST_PLUGIN_BUILD_FAILS    build() fails
 *   HPRT_TEST_PLUGIN_MALFORMED      corrupts answers by ray index in the batch
 *   HPRT_TEST_PLUGIN_OPTIONS_ECHO   correct, takes options "" or "leaf=N" (N = 1..16)
 * Self-contained (not sharing code with examples/) so that the tests do not
 * depend on the example. Build with hidden visibility. */
#include <hprt/plugin.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(HPRT_TEST_PLUGIN_GOOD) + defined(HPRT_TEST_PLUGIN_BAD_ABI) +                \
        defined(HPRT_TEST_PLUGIN_NULL_INTERSECT) + defined(HPRT_TEST_PLUGIN_NO_ENTRY) + \
        defined(HPRT_TEST_PLUGIN_ENTRY_NULL) + defined(HPRT_TEST_PLUGIN_CREATE_FAILS) + \
        defined(HPRT_TEST_PLUGIN_BUILD_FAILS) + defined(HPRT_TEST_PLUGIN_MALFORMED) +   \
        defined(HPRT_TEST_PLUGIN_OPTIONS_ECHO) + defined(HPRT_TEST_PLUGIN_SILENT) +     \
        defined(HPRT_TEST_PLUGIN_KEEP) !=                                               \
    1
#error "define exactly one HPRT_TEST_PLUGIN_* variant"
#endif

/* The variant as a constant, so that the code below stays plain C (folded
 * away by the compiler) and every function is referenced in every variant. */
enum {
  TP_GOOD,
  TP_BAD_ABI,
  TP_NULL_INTERSECT,
  TP_NO_ENTRY,
  TP_ENTRY_NULL,
  TP_CREATE_FAILS,
  TP_BUILD_FAILS,
  TP_MALFORMED,
  TP_OPTIONS_ECHO,
  TP_SILENT, /* writes no answer at all, and its name has control characters */
  TP_KEEP    /* update() keeps the build's mesh records: reads the arrays hprt moved in place */
};
#if defined(HPRT_TEST_PLUGIN_GOOD)
#define TP_VARIANT TP_GOOD
#elif defined(HPRT_TEST_PLUGIN_BAD_ABI)
#define TP_VARIANT TP_BAD_ABI
#elif defined(HPRT_TEST_PLUGIN_NULL_INTERSECT)
#define TP_VARIANT TP_NULL_INTERSECT
#elif defined(HPRT_TEST_PLUGIN_NO_ENTRY)
#define TP_VARIANT TP_NO_ENTRY
#elif defined(HPRT_TEST_PLUGIN_ENTRY_NULL)
#define TP_VARIANT TP_ENTRY_NULL
#elif defined(HPRT_TEST_PLUGIN_CREATE_FAILS)
#define TP_VARIANT TP_CREATE_FAILS
#elif defined(HPRT_TEST_PLUGIN_BUILD_FAILS)
#define TP_VARIANT TP_BUILD_FAILS
#elif defined(HPRT_TEST_PLUGIN_MALFORMED)
#define TP_VARIANT TP_MALFORMED
#elif defined(HPRT_TEST_PLUGIN_SILENT)
#define TP_VARIANT TP_SILENT
#elif defined(HPRT_TEST_PLUGIN_KEEP)
#define TP_VARIANT TP_KEEP
#else
#define TP_VARIANT TP_OPTIONS_ECHO
#endif

#define TP_MISS 0xFFFFFFFFu

struct hprt_backend {
  hprt_mesh* meshes; /* copies of the records; the arrays stay hprt's */
  uint32_t mesh_count;
  int leaf; /* OPTIONS_ECHO's parsed option (unused otherwise) */
};

/* ---- Brute force, watertight in double (as examples/plugin_bruteforce_c). ---- */

typedef struct {
  double x, y, z;
} dv;

static dv dsub(dv a, dv b) { return (dv){a.x - b.x, a.y - b.y, a.z - b.z}; }
static dv dcross(dv a, dv b) {
  return (dv){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static double ddot(dv a, dv b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static int dless(dv a, dv b) { return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z; }
/* d . (p x q), operands in a fixed order: exactly antisymmetric in p, q. */
static double edge(dv d, dv p, dv q) {
  return dless(q, p) ? -ddot(d, dcross(q, p)) : ddot(d, dcross(p, q));
}

static int vertex(const hprt_mesh* m, uint32_t i, dv* out) {
  if (i >= m->vertex_count) return 0;
  const float* p = m->vertices + 3 * (size_t)i;
  if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) return 0;
  *out = (dv){p[0], p[1], p[2]};
  return 1;
}

static int ray_valid(const hprt_ray* r) {
  const float c[6] = {r->org_x, r->org_y, r->org_z, r->dir_x, r->dir_y, r->dir_z};
  for (int k = 0; k < 6; ++k)
    if (!(fabsf(c[k]) <= 1.844e18f)) return 0; /* NaN fails too */
  if (c[3] == 0.0f && c[4] == 0.0f && c[5] == 0.0f) return 0;
  return r->tnear >= 0.0f && r->tnear <= r->tfar;
}

/* Closest hit (any = 0) or first hit (any = 1) in (tnear, tfar]. */
static int trace(const hprt_backend* be, const hprt_ray* ray, int any, hprt_hit* h) {
  *h = (hprt_hit){INFINITY, 0.0f, 0.0f, TP_MISS, TP_MISS};
  if (!ray_valid(ray)) return 0;
  const dv o = {ray->org_x, ray->org_y, ray->org_z}, d = {ray->dir_x, ray->dir_y, ray->dir_z};
  for (uint32_t g = 0; g < be->mesh_count; ++g) {
    const hprt_mesh* m = &be->meshes[g];
    for (uint32_t p = 0; p < m->triangle_count; ++p) {
      const uint32_t* ix = m->indices + 3 * (size_t)p;
      dv a, b, c;
      if (!vertex(m, ix[0], &a) || !vertex(m, ix[1], &b) || !vertex(m, ix[2], &c)) continue;
      const dv n = dcross(dsub(b, a), dsub(c, a));
      if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) continue; /* zero area */
      const dv A = dsub(a, o), B = dsub(b, o), C = dsub(c, o);
      const double U = edge(d, B, C), V = edge(d, C, A), W = edge(d, A, B);
      if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) continue;
      const double det = U + V + W, nd = ddot(n, d);
      if (det == 0.0 || nd == 0.0) continue;
      const float t = (float)(ddot(n, A) / nd);
      if (!isfinite(t) || !(ray->tnear < t && t <= ray->tfar) || !(t < h->t)) continue;
      float u = (float)(V / det), v = (float)(W / det);
      u = u > 0.0f ? (u < 1.0f ? u : 1.0f) : 0.0f; /* rounding may leave [0, 1] */
      v = v > 0.0f ? v : 0.0f;
      if ((double)u + v > 1.0) v = 1.0f - u;
      while ((double)u + v > 1.0) v = nextafterf(v, 0.0f);
      *h = (hprt_hit){t, u, v, g, p};
      if (any) return 1;
    }
  }
  return h->geom_id != TP_MISS;
}

/* ---- The ABI functions, with each variant's fault. ---- */

static void set_error(char* error, size_t size, const char* message) {
  if (error && size > 0) snprintf(error, size, "%s", message);
}

/* OPTIONS_ECHO: "" or "leaf=N", N = 1..16 (written out: strtol would take
 * spaces and signs). Returns N, 0 for "", -1 when malformed. */
static int parse_leaf(const char* s) {
  if (s[0] == '\0') return 0;
  if (strncmp(s, "leaf=", 5) != 0) return -1;
  s += 5;
  int n = 0, digits = 0;
  for (; *s >= '0' && *s <= '9' && digits < 3; ++s, ++digits) n = n * 10 + (*s - '0');
  return (*s == '\0' && digits > 0 && n >= 1 && n <= 16) ? n : -1;
}

static hprt_backend* tp_create(const char* options, int threads, char* error, size_t size) {
  (void)threads;
  if (!options) options = "";
  if (TP_VARIANT == TP_CREATE_FAILS) {
    set_error(error, size, "this plugin always fails to create");
    return NULL;
  }
  const int leaf = TP_VARIANT == TP_OPTIONS_ECHO ? parse_leaf(options) : (options[0] ? -1 : 0);
  if (leaf < 0) {
    if (error && size > 0) snprintf(error, size, "unknown option '%s'", options);
    return NULL;
  }
  hprt_backend* be = calloc(1, sizeof *be);
  if (!be) {
    set_error(error, size, "out of memory");
    return NULL;
  }
  be->leaf = leaf;
  return be;
}

/* Keeps the mesh records (not the arrays); also GOOD's update(). */
static int tp_build(hprt_backend* be, const hprt_mesh* meshes, uint32_t count, char* error,
                    size_t size) {
  if (TP_VARIANT == TP_BUILD_FAILS) {
    set_error(error, size, "mesh rejected by test plugin");
    return 1;
  }
  hprt_mesh* copy = count ? calloc(count, sizeof *copy) : NULL;
  free(be->meshes);
  be->meshes = copy;
  be->mesh_count = copy ? count : 0;
  if (count && !copy) {
    set_error(error, size, "out of memory");
    return 1;
  }
  if (count) memcpy(copy, meshes, count * sizeof *copy);
  return 0;
}

/* KEEP's update(): the records of the last build() stay, so the vertices it
 * reads are the arrays hprt wrote the new frame into (plugin.h, Memory). */
static int tp_keep_update(hprt_backend* be, const hprt_mesh* meshes, uint32_t count, char* error,
                          size_t size) {
  (void)meshes;
  if (count != be->mesh_count) {
    set_error(error, size, "update() with other meshes than build()");
    return 1;
  }
  return 0;
}

static void tp_intersect(const hprt_backend* be, const hprt_ray* rays, hprt_hit* hits,
                         size_t count) {
  if (TP_VARIANT == TP_SILENT) return;
  for (size_t i = 0; i < count; ++i) {
    hprt_hit* h = &hits[i];
    if (!trace(be, &rays[i], 0, h) || TP_VARIANT != TP_MALFORMED) continue;
    /* MALFORMED: break each hit by its index in this batch (hprt may split
     * batches, so which rays get which fault is not fixed). */
    if (i % 4 == 0) h->t = rays[i].tfar * 2.0f + 1.0f; /* outside [tnear, tfar] */
    if (i % 4 == 1) h->prim_id = be->meshes[h->geom_id].triangle_count + 5; /* out of range */
    if (i % 4 == 2) h->u = 1.5f; /* outside the triangle */
  }
}

static void tp_occluded(const hprt_backend* be, const hprt_ray* rays, uint8_t* occluded,
                        size_t count) {
  if (TP_VARIANT == TP_SILENT) return;
  for (size_t i = 0; i < count; ++i) {
    hprt_hit h;
    const int hit = trace(be, &rays[i], 1, &h);
    /* MALFORMED: 2 is neither 0 nor 1. */
    occluded[i] = (uint8_t)(hit && TP_VARIANT == TP_MALFORMED && i % 2 == 1 ? 2 : hit);
  }
}

static void tp_destroy(hprt_backend* be) {
  if (!be) return;
  free(be->meshes);
  free(be);
}

static const hprt_plugin_v1 tp_plugin = {
    .abi_version = TP_VARIANT == TP_BAD_ABI ? 2u : HPRT_PLUGIN_ABI_VERSION,
    .name = TP_VARIANT == TP_SILENT ? "si\nlent\x1b[0m" : "test",
    .create = tp_create,
    .build = tp_build,
    .update = TP_VARIANT == TP_GOOD   ? tp_build
              : TP_VARIANT == TP_KEEP ? tp_keep_update
                                      : NULL, /* NULL: hprt calls build() again */
    .intersect = TP_VARIANT == TP_NULL_INTERSECT ? NULL : tp_intersect,
    .occluded = tp_occluded,
    .destroy = tp_destroy,
};

#ifdef HPRT_TEST_PLUGIN_NO_ENTRY /* the preprocessor cannot see TP_VARIANT's value */
/* Exports something, but not the entry point hprt looks for. */
HPRT_PLUGIN_EXPORT const hprt_plugin_v1* hprt_test_plugin_not_the_entry(void) { return &tp_plugin; }
#else
HPRT_PLUGIN_EXPORT const hprt_plugin_v1* hprt_plugin_entry(void) {
  return TP_VARIANT == TP_ENTRY_NULL ? NULL : &tp_plugin;
}
#endif
