// Packet traversal (bvh/traverse_packet.h) answers every ray exactly as the
// single-ray traversal of the same layout (bvh2, bvh4, bvh8) does: same hit or miss, same t, u, v
// and ids bit for bit, same occlusion, for coherent and incoherent packets, mixed octants,
// axis-parallel rays with ±0 components, per-lane intervals and origins on
// the surface.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "bvh/flatten_wide.h"
#include "bvh/traverse.h"
#include "bvh/traverse_packet.h"
#include "bvh/traverse_wide.h"
#include "bvh/triangle_test_packet.h"
#include "bvh_test_meshes.h"
#include "bvh_trace_helpers.h"

using namespace hprt;

#if defined(HPRT_HAS_PACKETS)
namespace {

template <typename Test, bool kAnyHit, int N>
bool trace_single(const WideBvh<N>& w, const Ray& ray, Hit& hit) {
  return traverse_wide<Test, kAnyHit>(w, ray, hit);
}
template <typename Test, bool kAnyHit>
bool trace_single(const FlatBvh& b, const Ray& ray, Hit& hit) {
  return traverse<Test, kAnyHit>(b, ray, hit);
}

// Traces `rays` (a multiple of 16, all valid) as packets and one by one;
// returns how many rays hit.
template <typename Test, typename Bvh>
size_t expect_packets_match_single(const Bvh& w, const std::vector<Ray>& rays, const char* what) {
  EXPECT_EQ(rays.size() % kPacketSize, 0u);
  std::vector<Hit> packet_hits(rays.size());
  std::vector<uint8_t> packet_occ(rays.size(), 7);
  for (size_t g = 0; g + kPacketSize <= rays.size(); g += kPacketSize) {
    traverse_packet<Test, false>(w, &rays[g], &packet_hits[g], nullptr);
    traverse_packet<Test, true>(w, &rays[g], nullptr, &packet_occ[g]);
  }
  size_t hits = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_TRUE(ray_is_valid(rays[i])) << what << " ray " << i;
    Hit single, any;
    const bool found = trace_single<Test, false>(w, rays[i], single);
    const bool occluded = trace_single<Test, true>(w, rays[i], any);
    EXPECT_EQ(found, occluded) << what << " ray " << i;
    hits += found;
    if (!found) single = Hit{};
    EXPECT_EQ(std::memcmp(&single, &packet_hits[i], sizeof(Hit)), 0)
        << what << " ray " << i << ": single t " << single.t << " prim " << single.prim_id
        << ", packet t " << packet_hits[i].t << " prim " << packet_hits[i].prim_id;
    EXPECT_EQ(packet_occ[i], occluded ? 1 : 0) << what << " ray " << i;
  }
  return hits;
}

template <typename Test, int N>
void check_mesh(const std::vector<TriangleMesh>& meshes, int leaf, uint64_t seed) {
  BuildOptions o;
  o.max_leaf_size = leaf;
  const test::BuiltBvh b = test::build_flat(meshes, o);
  const auto layout = [&] {
    if constexpr (N == 2)
      return b.bvh;
    else
      return flatten_wide<N>(b.tree, b.prims, b.scene);
  };
  const auto w = layout();
  const AABB box = b.scene.bounds();
  const size_t coherent_hits =
      expect_packets_match_single<Test>(w, test::coherent_rays(box, 48, 32), "coherent");
  EXPECT_GT(coherent_hits, 48u * 32u / 20u);
  // Incoherent packets are not what the backend sends, but must be exact too.
  const size_t random_hits =
      expect_packets_match_single<Test>(w, test::random_rays(box, 1600, seed), "random");
  EXPECT_GT(random_hits, 1600u / 20u);
}

TEST(TraversePacket, MatchesSingleRaysOnSoupGridAndSphere) {
  for (int leaf : {1, 4, 8}) {
    SCOPED_TRACE(leaf);
    check_mesh<WatertightTest, 8>({test::random_soup(3000, 5, 0.05f)}, leaf, 11);
    check_mesh<MollerTest, 8>({test::random_soup(3000, 6, 0.05f)}, leaf, 12);
    check_mesh<WatertightTest, 4>({test::grid(40, 40), test::icosphere(3)}, leaf, 13);
    check_mesh<MollerTest, 4>({test::icosphere(4)}, leaf, 14);
    check_mesh<WatertightTest, 8>({test::grid(64, 64)}, leaf, 15);
    check_mesh<WatertightTest, 2>({test::random_soup(3000, 7, 0.05f)}, leaf, 16);
    check_mesh<MollerTest, 2>({test::grid(40, 40), test::icosphere(3)}, leaf, 17);
  }
}

// Packets whose lanes differ in the ways single rays may: axis-parallel rays
// with +0 and -0 components whose origins lie on the grid's vertex lines
// (shared edges and vertices: ties between triangles), every direction octant
// in one packet, per-lane intervals that end exactly at, or just before, the
// hit, and rays that start on the surface.
TEST(TraversePacket, HardLanesMatchSingleRays) {
  const test::BuiltBvh b = test::build_flat({test::grid(16, 16)}, BuildOptions{});
  const WideBvh<8> w8 = flatten_wide<8>(b.tree, b.prims, b.scene);
  const WideBvh<4> w4 = flatten_wide<4>(b.tree, b.prims, b.scene);
  std::vector<Ray> rays;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {  // vertex lines x = i/16, y = j/16, straight down
      Ray r;
      r.org = {float(i) / 16, float(j) / 16, 1.0f};
      r.dir = {(i & 1) ? -0.0f : 0.0f, (j & 1) ? -0.0f : 0.0f, -1.0f};
      rays.push_back(r);
    }
  test::Rng rng(21);
  for (int k = 0; k < 64; ++k) {  // all octants, origins above and below
    Ray r;
    r.org = {rng.uniform(), rng.uniform(), (k & 1) ? 0.7f : -0.7f};
    r.dir = {(k & 2) ? -0.2f : 0.2f, (k & 4) ? -0.3f : 0.3f, (k & 1) ? -1.0f : 1.0f};
    rays.push_back(r);
  }
  // Per-lane intervals around each lane's own hit: [0, t], [0, t-], [t, inf].
  std::vector<Ray> limited = rays;
  for (size_t i = 0; i < limited.size(); ++i) {
    Hit h;
    if (!traverse_wide<WatertightTest, false>(w8, rays[i], h)) continue;
    switch (i % 4) {
      case 0:
        limited[i].tfar = h.t;
        break;
      case 1:
        limited[i].tfar = std::nextafter(h.t, 0.0f);
        break;
      case 2:
        limited[i].tnear = h.t;
        break;
      default:
        break;
    }
  }
  // Origins on the surface: start at each lane's hit point, same direction.
  std::vector<Ray> on_surface = rays;
  for (size_t i = 0; i < on_surface.size(); ++i) {
    Hit h;
    if (traverse_wide<WatertightTest, false>(w8, rays[i], h))
      on_surface[i].org = rays[i].org + rays[i].dir * h.t;
  }
  EXPECT_GT((expect_packets_match_single<WatertightTest>(w8, rays, "hard bvh8")), 200u);
  expect_packets_match_single<MollerTest>(w8, rays, "hard bvh8 mt");
  expect_packets_match_single<WatertightTest>(w4, rays, "hard bvh4");
  expect_packets_match_single<WatertightTest>(w8, limited, "limited");
  expect_packets_match_single<MollerTest>(w4, limited, "limited mt");
  expect_packets_match_single<WatertightTest>(w8, on_surface, "on surface");
  expect_packets_match_single<WatertightTest>(b.bvh, rays, "hard bvh2");
  expect_packets_match_single<MollerTest>(b.bvh, limited, "limited bvh2 mt");
  expect_packets_match_single<WatertightTest>(b.bvh, on_surface, "on surface bvh2");
}

// The 16-lane watertight test against the scalar one, bit for bit: rays
// through a fan of triangles sharing edges and a vertex (hits exactly on
// edges, ties), degenerate triangles, intervals ending at the hit.
TEST(WatertightLanes, MatchesScalarTestBitForBit) {
  test::Rng rng(77);
  LeafTriangles tris;
  const Vec3f centre{0.3f, -0.2f, 2.0f};
  std::vector<TriangleVerts> verts;
  for (int k = 0; k < 12; ++k) {  // a fan around `centre`
    const float a0 = 0.5236f * k, a1 = 0.5236f * (k + 1);
    verts.push_back({centre, centre + Vec3f{std::cos(a0), std::sin(a0), 0.1f * k},
                     centre + Vec3f{std::cos(a1), std::sin(a1), 0.1f * (k + 1)}});
  }
  verts.push_back({centre, centre, centre + Vec3f{1, 0, 0}});                   // zero area
  verts.push_back({centre, centre + Vec3f{1, 1, 0}, centre + Vec3f{2, 2, 0}});  // a line
  tris.allocate(verts.size());
  for (size_t i = 0; i < verts.size(); ++i) tris.verts[i] = verts[i];
  size_t hits = 0, compared = 0;
  for (int round = 0; round < 400; ++round) {
    // 16 rays from one eye, aimed at fan vertices, edge points and interiors;
    // the eye moves round the fan so every (kx, ky, kz) occurs.
    const Vec3f eye = centre + Vec3f{3.0f * (rng.uniform() - 0.5f), 3.0f * (rng.uniform() - 0.5f),
                                     (round % 2 ? 4.0f : -4.0f) * (0.5f + rng.uniform())};
    Ray rays[16];
    WatertightTest::Prepared prep[16];
    float tnear[16], tfar[16];
    for (int l = 0; l < 16; ++l) {
      const TriangleVerts& v = verts[size_t(rng.uniform() * 12) % 12];
      const float s = (l % 4 == 0) ? 0.0f : rng.uniform(), q = (l % 3 == 0) ? 0.0f : rng.uniform();
      const Vec3f target = v.v0 + (v.v1 - v.v0) * s + (v.v2 - v.v0) * (q * (1.0f - s));
      rays[l].org = eye;
      rays[l].dir = target - eye;
      prep[l] = WatertightTest::prepare(rays[l]);
      tnear[l] = l % 5 == 0 ? 0.5f : 0.0f;
      tfar[l] = l % 7 == 0 ? 1.0f : 1e30f;
    }
    WatertightLanes lanes;
    lanes.setup(prep, tnear);
    bool same_axes = true;
    for (int l = 1; l < 16; ++l)
      same_axes = same_axes && prep[l].kx == prep[0].kx && prep[l].kz == prep[0].kz;
    ASSERT_EQ(lanes.usable(), same_axes);
    if (!lanes.usable()) continue;
    for (uint32_t i = 0; i < verts.size(); ++i) {
      alignas(64) float t[16], u[16], v[16];
      const __mmask16 mask = lanes.intersect(tris, i, tfar, 0xFFFF, t, u, v);
      for (int l = 0; l < 16; ++l) {
        TriangleHit h{};
        const bool hit = WatertightTest::intersect(prep[l], tris, i, tnear[l], tfar[l], h);
        ++compared;
        ASSERT_EQ(hit, bool((mask >> l) & 1)) << "round " << round << " triangle " << i;
        if (!hit) continue;
        ++hits;
        EXPECT_EQ(std::memcmp(&h.t, &t[l], 4), 0);
        EXPECT_EQ(std::memcmp(&h.u, &u[l], 4), 0);
        EXPECT_EQ(std::memcmp(&h.v, &v[l], 4), 0);
      }
    }
  }
  EXPECT_GT(compared, 20000u);
  EXPECT_GT(hits, compared / 40);
}

// A tree that is a single leaf: the binary root's box is tested first, the
// wide root is a leaf reference.
TEST(TraversePacket, SingleLeafTrees) {
  const test::BuiltBvh b = test::build_flat({test::grid(1, 1)}, BuildOptions{});
  ASSERT_TRUE(b.bvh.nodes[0].is_leaf());
  const WideBvh<8> w = flatten_wide<8>(b.tree, b.prims, b.scene);
  ASSERT_TRUE(w.root.is_leaf());
  const auto rays = test::coherent_rays(b.scene.bounds(), 16, 16);
  EXPECT_GT((expect_packets_match_single<WatertightTest>(b.bvh, rays, "leaf bvh2")), 16u);
  EXPECT_GT((expect_packets_match_single<MollerTest>(w, rays, "leaf bvh8")), 16u);
}

TEST(TraversePacket, EmptyTreeMissesEveryLane) {
  std::vector<Ray> rays(kPacketSize);
  for (Ray& r : rays) r.dir = {0, 0, 1};
  std::vector<Hit> hits(kPacketSize, Hit{1.0f, 0.5f, 0.5f, 0, 0});
  std::vector<uint8_t> occ(kPacketSize, 1);
  traverse_packet<WatertightTest, false>(WideBvh<8>{}, rays.data(), hits.data(), nullptr);
  traverse_packet<WatertightTest, true>(WideBvh<4>{}, rays.data(), nullptr, occ.data());
  for (int l = 0; l < kPacketSize; ++l) {
    EXPECT_FALSE(hits[l].hit());
    EXPECT_EQ(occ[l], 0);
  }
  hits.assign(kPacketSize, Hit{1.0f, 0.5f, 0.5f, 0, 0});
  occ.assign(kPacketSize, 1);
  traverse_packet<MollerTest, false>(FlatBvh{}, rays.data(), hits.data(), nullptr);
  traverse_packet<MollerTest, true>(FlatBvh{}, rays.data(), nullptr, occ.data());
  for (int l = 0; l < kPacketSize; ++l) {
    EXPECT_FALSE(hits[l].hit());
    EXPECT_EQ(occ[l], 0);
  }
}

}  // namespace
#else
TEST(TraversePacket, NeedsAvx512) { GTEST_SKIP() << "built without AVX-512F: no packet traversal"; }
#endif
