// Packet traversal (bvh/traverse/traverse_packet.h) answers every ray exactly as the
// single-ray traversal of the same layout (bvh2, bvh4, bvh8) does: same hit or
// miss, same t, u, v and ids bit for bit, same occlusion, for coherent and
// incoherent packets, mixed octants, axis-parallel rays with ±0 components,
// per-lane intervals and origins on the surface; the frustum culls no child a
// lane enters. The watertight test on lanes (over the rays of a packet, or
// over the triangles of a leaf) equals the scalar one bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "bvh/intersect/ray_triangle_lanes.h"
#include "bvh/layout/flatten_wide.h"
#include "bvh/traverse/traverse_bvh2.h"
#include "bvh/traverse/traverse_packet.h"
#include "bvh/traverse/traverse_wide.h"
#include "tests/support/bvh_test_meshes.h"
#include "tests/support/bvh_trace_helpers.h"

namespace hprt {

#if defined(HPRT_HAS_PACKETS)
namespace {

// The box of some triangles: the lane tests' error bound needs the tree's box
// (WatertightTest::prepare); without one every lane goes to the scalar test.
AABB bounds_of_verts(const std::vector<TriangleVerts>& verts) {
  AABB b;
  for (const TriangleVerts& v : verts) {
    b.extend(v.v0);
    b.extend(v.v1);
    b.extend(v.v2);
  }
  return b;
}

template <typename Test, bool kAnyHit, int N>
bool trace_single(const WideBvh<N>& w, const Ray& ray, Hit& hit) {
  return traverse_wide<Test, kAnyHit>(w, ray, hit);
}
template <typename Test, bool kAnyHit>
bool trace_single(const Bvh2& b, const Ray& ray, Hit& hit) {
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

// Packets whose lanes share direction signs are culled against their
// frustum before the lane test. The frustum keeps every child that any lane's
// own box test enters, at every node of bvh8 and bvh4, for packets that stress
// its bounds: origins on the box planes, spread over the whole scene or all
// in one point, direction components from 1e-20 to 1e18 (reciprocals up to
// 1e20), per-lane intervals from empty to unbounded; and such packets
// answer as their rays traced one by one.
template <int N>
size_t expect_frustum_keeps_lane_hits(const WideBvh<N>& w, const std::vector<Ray>& rays) {
  const detail::PacketNodes<WideBvh<N>> layout{w};
  size_t culled = 0;
  for (size_t g = 0; g + kPacketSize <= rays.size(); g += kPacketSize) {
    const detail::RayPacket<WatertightTest> packet(&rays[g], w.bounds);
    EXPECT_TRUE(packet.frustum) << "packet " << g / kPacketSize;
    const __m512 tfar = _mm512_load_ps(packet.tfar_lane);
    const float tfar_max = detail::reduce_max16(tfar);
    for (uint32_t n = 0; n < w.nodes.size(); ++n) {
      const unsigned slots = layout.frustum_slots(NodeRef::inner(n), packet, tfar_max);
      for (int i = 0; i < N && !w.nodes[n].child[i].empty(); ++i) {
        __m512 entry;
        const __mmask16 lanes =
            detail::slab_packet(packet, detail::WideSlot<N>{w.nodes[n], i}, tfar, 0xFFFF, entry);
        if (lanes) {
          EXPECT_TRUE(slots >> i & 1u) << "node " << n << " slot " << i;
        }
        culled += !(slots >> i & 1u);
      }
    }
  }
  return culled;
}

TEST(TraversePacket, FrustumKeepsEveryChildALaneEnters) {
  const test::BuiltBvh b =
      test::build_flat({test::grid(24, 24), test::icosphere(2)}, BuildOptions{});
  const WideBvh<8> w8 = flatten_wide<8>(b.tree, b.prims, b.scene);
  const WideBvh<4> w4 = flatten_wide<4>(b.tree, b.prims, b.scene);
  const AABB box = b.scene.bounds();
  // Box planes of the tree's nodes, as origin coordinates.
  std::vector<float> planes[3];
  for (const WideNode<8>& node : w8.nodes)
    for (int i = 0; i < 8 && !node.child[i].empty(); ++i)
      for (int a = 0; a < 3; ++a) {
        planes[a].push_back(node.bounds[2 * a][i]);
        planes[a].push_back(node.bounds[2 * a + 1][i]);
      }
  test::Rng rng(31);
  const auto pick = [&](const std::vector<float>& v) { return v[rng.next() % v.size()]; };
  std::vector<Ray> rays;
  for (int p = 0; p < 96; ++p) {
    const int octant = p % 8, kind = p / 8 % 4;
    const Vec3f eye = box.min + (box.max - box.min) * Vec3f(rng.uniform(), rng.uniform(), 2.0f);
    for (int l = 0; l < kPacketSize; ++l) {
      Ray r;
      for (int a = 0; a < 3; ++a) {
        float d = 0.05f + rng.uniform();
        if (kind == 1) d = std::pow(10.0f, -20.0f + 38.0f * rng.uniform());  // 1e-20 .. 1e18
        r.dir[a] = (octant >> a & 1) ? -d : d;
        r.org[a] = kind == 3 ? eye[a] : pick(planes[a]);
      }
      if (kind == 2) r.dir = (box.min + (box.max - box.min) * 0.5f) - r.org;  // through the middle
      if (kind == 2)
        for (int a = 0; a < 3; ++a)
          if (r.dir[a] == 0.0f || std::signbit(r.dir[a]) != bool(octant >> a & 1))
            r.dir[a] = (octant >> a & 1) ? -1e-3f : 1e-3f;
      switch (l % 4) {
        case 0:
          r.tfar = 0.0f;
          break;
        case 1:
          r.tnear = 0.5f * rng.uniform();
          r.tfar = r.tnear + rng.uniform();
          break;
        default:
          break;
      }
      rays.push_back(r);
    }
  }
  EXPECT_GT(expect_frustum_keeps_lane_hits(w8, rays), 0u);
  EXPECT_GT(expect_frustum_keeps_lane_hits(w4, rays), 0u);
  expect_packets_match_single<WatertightTest>(w8, rays, "frustum bvh8");
  expect_packets_match_single<WatertightTest>(w4, rays, "frustum bvh4");
  expect_packets_match_single<MollerTest>(w8, rays, "frustum bvh8 mt");
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
  const LeafRange all = LeafRange::whole(0, uint32_t(verts.size()));
  for (uint32_t i = 0; i < verts.size(); ++i)
    tris.set_triangle(all, i, verts[i].v0, verts[i].v1, verts[i].v2);
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
      prep[l] = WatertightTest::prepare(rays[l], bounds_of_verts(verts));
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
      const __mmask16 mask = lanes.intersect(tris, all, i, tfar, 0xFFFF, t, u, v);
      for (int l = 0; l < 16; ++l) {
        TriangleHit h{};
        const bool hit = WatertightTest::intersect(prep[l], verts[i].v0, verts[i].v1, verts[i].v2,
                                                   tnear[l], tfar[l], h);
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

// The fan of MatchesScalarTestBitForBit with every triangle twice in a row
// (so a leaf window holds exact duplicates, ties in t, besides triangles
// sharing edges and vertices), a zero-area triangle and a line.
std::vector<TriangleVerts> fan_with_duplicates(const Vec3f& centre) {
  std::vector<TriangleVerts> verts;
  for (int k = 0; k < 12; ++k) {
    const float a0 = 0.5236f * k, a1 = 0.5236f * (k + 1);
    const TriangleVerts t{centre, centre + Vec3f{std::cos(a0), std::sin(a0), 0.1f * k},
                          centre + Vec3f{std::cos(a1), std::sin(a1), 0.1f * (k + 1)}};
    verts.push_back(t);
    verts.push_back(t);
  }
  verts.push_back({centre, centre, centre + Vec3f{1, 0, 0}});
  verts.push_back({centre, centre + Vec3f{1, 1, 0}, centre + Vec3f{2, 2, 0}});
  return verts;
}

// A ray from a random eye round the fan at a vertex, edge point or interior
// point of one of its triangles, with one of a few intervals.
Ray fan_probe(test::Rng& rng, const std::vector<TriangleVerts>& verts, const Vec3f& centre, int k) {
  const Vec3f eye = centre + Vec3f{3.0f * (rng.uniform() - 0.5f), 3.0f * (rng.uniform() - 0.5f),
                                   (k % 2 ? 4.0f : -4.0f) * (0.5f + rng.uniform())};
  const TriangleVerts& v = verts[size_t(rng.uniform() * 24) % 24];
  const float s = (k % 4 == 0) ? 0.0f : rng.uniform(), q = (k % 3 == 0) ? 0.0f : rng.uniform();
  const Vec3f target = v.v0 + (v.v1 - v.v0) * s + (v.v2 - v.v0) * (q * (1.0f - s));
  Ray r;
  r.org = eye;
  r.dir = target - eye;
  r.tnear = k % 5 == 0 ? 0.5f : 0.0f;
  r.tfar = k % 7 == 0 ? 1.0f : 1e30f;
  return r;
}

// `verts` as verts blocks: one block of all (a leaf is then a part of it,
// as a split leaf of a wide layout), or only the window [first, first +
// count) written as its own block. Returns the leaf to test.
LeafRange store_blocks(LeafTriangles& tris, const std::vector<TriangleVerts>& verts, bool own_block,
                       uint32_t first, uint32_t count) {
  const uint32_t n = uint32_t(verts.size());
  const LeafRange block = own_block ? LeafRange::whole(first, count) : LeafRange::whole(0, n);
  for (uint32_t i = block.first; i < block.first + block.count; ++i)
    tris.set_triangle(block, i, verts[i].v0, verts[i].v1, verts[i].v2);
  return {first, count, block.first, block.count};
}

// The fan with duplicates as leaf triangles (their verts blocks are written
// per test by store_blocks).
class WatertightLeaf : public ::testing::Test {
 protected:
  const Vec3f centre{0.3f, -0.2f, 2.0f};
  const std::vector<TriangleVerts> verts = fan_with_duplicates(centre);
  LeafTriangles tris;
  void SetUp() override { tris.allocate(verts.size(), TriangleArrays::kVerts); }
};

// The leaf test over 8 (and 4) triangle lanes against the scalar test on the
// raw vertices, bit for bit, for every window of 1..8 triangles, as its own
// verts block and as a part of a larger one (windows ending at the array's
// end too: the masked loads must not read past it).
TEST_F(WatertightLeaf, MatchesScalarTestBitForBit) {
  test::Rng rng(78);
  size_t hits = 0, compared = 0;
  for (int k = 0; k < 300; ++k) {
    const Ray ray = fan_probe(rng, verts, centre, k);
    const WatertightTest::Prepared prep = WatertightTest::prepare(ray, bounds_of_verts(verts));
    for (bool own_block : {false, true})
      for (uint32_t count = 1; count <= 8; ++count)
        for (uint32_t first = 0; first + count <= verts.size(); first += 3) {
          const LeafRange leaf = store_blocks(tris, verts, own_block, first, count);
          alignas(32) float t[8], u[8], v[8], t4[4], u4[4], v4[4];
          const unsigned mask =
              watertight_leaf<8>(prep, tris, leaf, first, count, ray.tnear, ray.tfar, t, u, v);
          ASSERT_EQ(mask >> count, 0u);
          if (count <= 4) {  // the 4-lane version: the same lanes, the same bits
            const unsigned mask4 =
                watertight_leaf<4>(prep, tris, leaf, first, count, ray.tnear, ray.tfar, t4, u4, v4);
            ASSERT_EQ(mask4, mask) << "ray " << k << " leaf " << first << "+" << count;
            for (uint32_t l = 0; l < count; ++l)
              if ((mask >> l) & 1) {
                EXPECT_EQ(std::memcmp(&t4[l], &t[l], 4), 0);
                EXPECT_EQ(std::memcmp(&u4[l], &u[l], 4), 0);
                EXPECT_EQ(std::memcmp(&v4[l], &v[l], 4), 0);
              }
          }
          for (uint32_t l = 0; l < count; ++l) {
            const TriangleVerts& tv = verts[first + l];
            TriangleHit h{};
            const bool hit =
                WatertightTest::intersect(prep, tv.v0, tv.v1, tv.v2, ray.tnear, ray.tfar, h);
            ++compared;
            ASSERT_EQ(hit, bool((mask >> l) & 1)) << "ray " << k << " triangle " << first + l;
            if (!hit) continue;
            ++hits;
            EXPECT_EQ(std::memcmp(&h.t, &t[l], 4), 0);
            EXPECT_EQ(std::memcmp(&h.u, &u[l], 4), 0);
            EXPECT_EQ(std::memcmp(&h.v, &v[l], 4), 0);
          }
        }
  }
  EXPECT_GT(compared, 50000u);
  EXPECT_GT(hits, compared / 40);
}

// intersect_leaf through the lanes (leaves of 2 or more) keeps exactly the hit
// the triangle-by-triangle loop keeps (the kStats instantiation runs the
// loop): leaves of 1..20 triangles (more than one chunk of 8), duplicates
// hit at the same t (the lower index wins), and a closest hit carried in from
// an earlier leaf at that same t with a lower or a higher index.
TEST_F(WatertightLeaf, LeafTestKeepsTheLoopsHit) {
  test::Rng rng(79);
  size_t closest_hits = 0, carried_ties = 0;
  for (int k = 0; k < 800; ++k) {
    const Ray ray = fan_probe(rng, verts, centre, k);
    const WatertightTest::Prepared prep = WatertightTest::prepare(ray, bounds_of_verts(verts));
    for (uint32_t count = 1; count <= 20; ++count)
      for (uint32_t first = 0; first + count <= verts.size(); first += 5) {
        const LeafRange leaf = store_blocks(tris, verts, (first + count) % 2 == 0, first, count);
        for (int carried = 0; carried < 3; ++carried) {
          ClosestHit before;
          float tfar = ray.tfar;
          if (carried > 0) {  // the loop's own best, as if found in another leaf
            ClosestHit probe;
            float probe_tfar = ray.tfar;
            TraversalStats stats;
            intersect_leaf<WatertightTest, false, true>(prep, tris, leaf, ray.tnear, probe_tfar,
                                                        probe, &stats);
            if (!probe.found) continue;
            before = probe;
            before.index = carried == 1 ? 0 : uint32_t(verts.size());
            tfar = probe_tfar;
            ++carried_ties;
          }
          for (bool any : {false, true}) {
            ClosestHit loop = before, lanes = before;
            float loop_tfar = tfar, lanes_tfar = tfar;
            TraversalStats stats;
            bool loop_ret, lanes_ret;
            if (any) {
              loop_ret = intersect_leaf<WatertightTest, true, true>(prep, tris, leaf, ray.tnear,
                                                                    loop_tfar, loop, &stats);
              lanes_ret = intersect_leaf<WatertightTest, true, false>(prep, tris, leaf, ray.tnear,
                                                                      lanes_tfar, lanes, nullptr);
            } else {
              loop_ret = intersect_leaf<WatertightTest, false, true>(prep, tris, leaf, ray.tnear,
                                                                     loop_tfar, loop, &stats);
              lanes_ret = intersect_leaf<WatertightTest, false, false>(prep, tris, leaf, ray.tnear,
                                                                       lanes_tfar, lanes, nullptr);
              closest_hits += loop.found && carried == 0;
            }
            ASSERT_EQ(loop_ret, lanes_ret) << "ray " << k << " leaf " << first << "+" << count;
            ASSERT_EQ(loop.found, lanes.found);
            EXPECT_EQ(loop.index, lanes.index) << "ray " << k << " leaf " << first << "+" << count;
            EXPECT_EQ(std::memcmp(&loop.best, &lanes.best, sizeof(TriangleHit)), 0);
            EXPECT_EQ(std::memcmp(&loop_tfar, &lanes_tfar, 4), 0);
          }
        }
      }
  }
  EXPECT_GT(closest_hits, 5000u);
  EXPECT_GT(carried_ties, 5000u);
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
  traverse_packet<MollerTest, false>(Bvh2{}, rays.data(), hits.data(), nullptr);
  traverse_packet<MollerTest, true>(Bvh2{}, rays.data(), nullptr, occ.data());
  for (int l = 0; l < kPacketSize; ++l) {
    EXPECT_FALSE(hits[l].hit());
    EXPECT_EQ(occ[l], 0);
  }
}

}  // namespace
#else
TEST(TraversePacket, NeedsAvx512) { GTEST_SKIP() << "built without AVX-512F: no packet traversal"; }
#endif

}  // namespace hprt
