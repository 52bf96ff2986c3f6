/* bruteforce: the simplest correct hprt plugin (see <hprt/plugin.h>). Every
 * ray is tested against every triangle of every mesh, so it is slow, but its
 * answers agree with hprt's exact arbiter: the test below is watertight and
 * evaluated in double precision.
 *
 * Built with -DHPRT_BRUTEFORCE_BROKEN it becomes "bruteforce-broken", which
 * ignores some triangles on purpose, to show `hprt validate rays` failing. */
#include <hprt/plugin.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The one difference between the two builds: which triangles trace() skips. */
#ifdef HPRT_BRUTEFORCE_BROKEN
/* Deliberately wrong: rays that should hit a triangle with prim_id % 5 == 2
 * report another triangle or a miss (in intersect and occluded alike). */
#define BF_NAME "bruteforce-broken"
#define BF_SKIPPED(prim) ((prim) % 5u == 2u)
#else
#define BF_NAME "bruteforce"
#define BF_SKIPPED(prim) 0
#endif

#define BF_INVALID_ID 0xFFFFFFFFu
/* Embree's FLT_LARGE: rays with a larger component are invalid (miss). */
#define BF_RAY_LIMIT 1.844e18f

struct hprt_backend {
  /* A copy of the mesh records; the vertex and index arrays they point to
   * belong to hprt and stay valid until the next build/update/destroy. */
  hprt_mesh* meshes;
  uint32_t mesh_count;
};

typedef struct {
  double x, y, z;
} dvec3;

/* A ray prepared for testing: origin and direction exactly as doubles. */
typedef struct {
  dvec3 o, d;
  float tnear, tfar;
} bf_ray;

static dvec3 sub3(dvec3 a, dvec3 b) {
  dvec3 r = {a.x - b.x, a.y - b.y, a.z - b.z};
  return r;
}
static dvec3 cross3(dvec3 a, dvec3 b) {
  dvec3 r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  return r;
}
static double dot3(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static int less3(dvec3 a, dvec3 b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

/* Edge function d . (p x q). Mathematically edge(d, q, p) = -edge(d, p, q);
 * always evaluating with the lesser of p, q first makes that hold exactly,
 * whatever the compiler contracts into FMAs, so the two triangles sharing an
 * edge see exactly opposite values and no ray slips between them. */
static double edge(dvec3 d, dvec3 p, dvec3 q) {
  return less3(q, p) ? -dot3(d, cross3(q, p)) : dot3(d, cross3(p, q));
}

/* Reads vertex i of m as doubles; 0 when its index or value is unusable. */
static int load_vertex(const hprt_mesh* m, uint32_t i, dvec3* out) {
  if (i >= m->vertex_count) return 0;
  const float* p = m->vertices + 3 * (size_t)i;
  if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) return 0;
  out->x = p[0];
  out->y = p[1];
  out->z = p[2];
  return 1;
}

/* The hprt definition of a valid ray (invalid rays miss); the comparisons are
 * written so that NaN fails them. */
static int load_ray(const hprt_ray* in, bf_ray* r) {
  const float c[6] = {in->org_x, in->org_y, in->org_z, in->dir_x, in->dir_y, in->dir_z};
  for (int k = 0; k < 6; ++k)
    if (!(fabsf(c[k]) <= BF_RAY_LIMIT)) return 0;
  if (c[3] == 0.0f && c[4] == 0.0f && c[5] == 0.0f) return 0;
  if (!(in->tnear >= 0.0f && in->tnear <= in->tfar)) return 0;
  r->o.x = c[0], r->o.y = c[1], r->o.z = c[2];
  r->d.x = c[3], r->d.y = c[4], r->d.z = c[5];
  r->tnear = in->tnear;
  r->tfar = in->tfar;
  return 1;
}

/* Ray r against triangle prim of m, double-sided. On a hit in (tnear, tfar]
 * (Embree 3's interval, as hprt's arbiter uses) fills t, u, v and returns 1. */
static int hit_triangle(const hprt_mesh* m, uint32_t prim, const bf_ray* r, float* t, float* u,
                        float* v) {
  const uint32_t* idx = m->indices + 3 * (size_t)prim;
  dvec3 a, b, c;
  if (!load_vertex(m, idx[0], &a) || !load_vertex(m, idx[1], &b) || !load_vertex(m, idx[2], &c))
    return 0;
  const dvec3 n = cross3(sub3(b, a), sub3(c, a));
  if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) return 0; /* zero area: never hit */

  const dvec3 A = sub3(a, r->o), B = sub3(b, r->o), C = sub3(c, r->o);
  /* U, V, W: unnormalised barycentrics of a, b, c. */
  const double U = edge(r->d, B, C), V = edge(r->d, C, A), W = edge(r->d, A, B);
  if (!((U >= 0.0 && V >= 0.0 && W >= 0.0) || (U <= 0.0 && V <= 0.0 && W <= 0.0))) return 0;
  const double det = U + V + W;
  const double nd = dot3(n, r->d);
  if (det == 0.0 || nd == 0.0) return 0; /* parallel to the plane */

  const float tf = (float)(dot3(n, A) / nd);
  /* isfinite: a t that overflows float must not pass for tfar = +inf. */
  if (!isfinite(tf) || !(r->tnear < tf && tf <= r->tfar)) return 0;
  /* Rounding can push u, v a hair outside the triangle; hprt would call
   * that malformed, so clamp into u, v >= 0, u + v <= 1. */
  float uf = (float)(V / det), vf = (float)(W / det);
  if (!(uf >= 0.0f)) uf = 0.0f;
  if (!(vf >= 0.0f)) vf = 0.0f;
  if (uf > 1.0f) uf = 1.0f;
  if ((double)uf + (double)vf > 1.0) {
    vf = 1.0f - uf; /* exact for uf >= 0.5, else off by at most a rounding */
    while ((double)uf + (double)vf > 1.0) vf = nextafterf(vf, 0.0f);
  }
  *t = tf;
  *u = uf;
  *v = vf;
  return 1;
}

/* The closest hit (any_hit = 0) or the first one found (any_hit = 1). Ties
 * keep the first in (geom_id, prim_id) order. Returns whether one was found. */
static int trace(const hprt_backend* be, const hprt_ray* ray, int any_hit, hprt_hit* best) {
  best->t = INFINITY;
  best->u = best->v = 0.0f;
  best->geom_id = best->prim_id = BF_INVALID_ID;
  bf_ray r;
  if (!load_ray(ray, &r)) return 0;
  int found = 0;
  for (uint32_t g = 0; g < be->mesh_count; ++g) {
    const hprt_mesh* m = &be->meshes[g];
    for (uint32_t p = 0; p < m->triangle_count; ++p) {
      float t, u, v;
      if (BF_SKIPPED(p) || !hit_triangle(m, p, &r, &t, &u, &v) || !(t < best->t)) continue;
      best->t = t;
      best->u = u;
      best->v = v;
      best->geom_id = g;
      best->prim_id = p;
      found = 1;
      if (any_hit) return 1;
    }
  }
  return found;
}

static void write_error(char* error, size_t error_size, const char* message) {
  if (error && error_size > 0) snprintf(error, error_size, "%s", message);
}

static hprt_backend* bf_create(const char* options, int threads, char* error, size_t error_size) {
  (void)threads; /* hprt calls from its own threads; nothing to size here */
  if (options && options[0] != '\0') {
    if (error && error_size > 0)
      snprintf(error, error_size, "unknown option '%s' (bruteforce takes no options)", options);
    return NULL;
  }
  hprt_backend* be = calloc(1, sizeof *be);
  if (!be) write_error(error, error_size, "out of memory");
  return be;
}

/* Also the update(): moved vertices need nothing but the new pointers. */
static int bf_build(hprt_backend* be, const hprt_mesh* meshes, uint32_t mesh_count, char* error,
                    size_t error_size) {
  hprt_mesh* copy = NULL;
  if (mesh_count > 0) {
    copy = calloc(mesh_count, sizeof *copy); /* calloc checks the size for overflow */
    if (!copy) {
      /* The old meshes may be gone after this call: drop them too. */
      free(be->meshes);
      be->meshes = NULL;
      be->mesh_count = 0;
      write_error(error, error_size, "out of memory");
      return 1;
    }
    memcpy(copy, meshes, mesh_count * sizeof *copy);
  }
  free(be->meshes);
  be->meshes = copy;
  be->mesh_count = mesh_count;
  return 0;
}

/* Read-only on the backend, so safe to call concurrently. */
static void bf_intersect(const hprt_backend* be, const hprt_ray* rays, hprt_hit* hits,
                         size_t count) {
  for (size_t i = 0; i < count; ++i) trace(be, &rays[i], 0, &hits[i]);
}

static void bf_occluded(const hprt_backend* be, const hprt_ray* rays, uint8_t* occluded,
                        size_t count) {
  for (size_t i = 0; i < count; ++i) {
    hprt_hit h;
    occluded[i] = (uint8_t)trace(be, &rays[i], 1, &h);
  }
}

static void bf_destroy(hprt_backend* be) {
  if (!be) return;
  free(be->meshes);
  free(be);
}

static const hprt_plugin_v1 bf_plugin = {
    .abi_version = HPRT_PLUGIN_ABI_VERSION,
    .name = BF_NAME,
    .create = bf_create,
    .build = bf_build,
    .update = bf_build,
    .intersect = bf_intersect,
    .occluded = bf_occluded,
    .destroy = bf_destroy,
};

HPRT_PLUGIN_EXPORT const hprt_plugin_v1* hprt_plugin_entry(void) { return &bf_plugin; }
