// .rays / .hits / occlusion files: round trips, size checks, missing files.
#include "io/rays/ray_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"

namespace fs = std::filesystem;

namespace hprt {
namespace {

class RayFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hprt_ray_file_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const char* name) const { return (dir_ / name).string(); }
  void write_bytes(const std::string& p, size_t n) const {
    std::ofstream(p, std::ios::binary) << std::string(n, 'x');
  }
  fs::path dir_;
};

TEST_F(RayFileTest, RaysRoundTripBitExact) {
  std::vector<Ray> rays(3);
  rays[0].org = {1, 2, 3};
  rays[0].dir = {-0.0f, 0.0f, 1.0f};
  rays[1].tnear = 0.5f;
  rays[1].tfar = 7.0f;
  rays[2].org = {std::numeric_limits<float>::quiet_NaN(), 1e-30f, -1e30f};
  const std::string p = path("a.rays");
  write_rays(p, rays);
  EXPECT_EQ(fs::file_size(p), 96u);
  const std::vector<Ray> back = read_rays(p);
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(std::memcmp(back.data(), rays.data(), 96), 0);
  EXPECT_TRUE(std::signbit(back[0].dir.x));
  // Field order in the file: org.x org.y org.z tnear dir.x dir.y dir.z tfar.
  float raw[8];
  std::ifstream(p, std::ios::binary).read(reinterpret_cast<char*>(raw), sizeof raw);
  EXPECT_EQ(raw[0], 1.0f);
  EXPECT_EQ(raw[2], 3.0f);
  EXPECT_EQ(raw[6], 1.0f);
  EXPECT_EQ(raw[7], std::numeric_limits<float>::infinity());
}

TEST_F(RayFileTest, HitsAndOcclusionRoundTrip) {
  std::vector<Hit> hits(2);
  hits[0] = {1.5f, 0.25f, 0.5f, 3u, 77u};
  const std::string ph = path("a.hits");
  write_hits(ph, hits);
  EXPECT_EQ(fs::file_size(ph), 40u);
  const std::vector<Hit> back = read_hits(ph);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].t, 1.5f);
  EXPECT_EQ(back[0].geom_id, 3u);
  EXPECT_EQ(back[0].prim_id, 77u);
  EXPECT_FALSE(back[1].hit());
  EXPECT_EQ(back[1].t, std::numeric_limits<float>::infinity());

  const std::vector<uint8_t> occ = {1, 0, 0, 1, 1};
  const std::string po = path("a.occ");
  write_occlusion(po, occ);
  EXPECT_EQ(fs::file_size(po), 5u);
  EXPECT_EQ(read_occlusion(po), occ);
}

TEST_F(RayFileTest, CountsAndHitListsRoundTrip) {
  const std::vector<uint32_t> counts = {0, 3, 1, 0xFFFFFFFFu};
  write_counts(path("c.bin"), counts);
  EXPECT_EQ(fs::file_size(path("c.bin")), 16u);
  EXPECT_EQ(read_counts(path("c.bin")), counts);

  HitLists lists;
  lists.offsets = {0, 2, 2, 3};
  lists.hits = {Hit{1.0f, 0.1f, 0.2f, 0, 7}, Hit{2.0f, 0.3f, 0.4f, 1, 8},
                Hit{0.5f, 0.0f, 1.0f, 2, 9}};
  lists.truncated = {0, 0, 1};
  write_hit_lists(path("a.bin"), lists);
  EXPECT_EQ(fs::file_size(path("a.bin")), 3 * 4 + 3 * 20u);
  const HitLists back = read_hit_lists(path("a.bin"));
  EXPECT_EQ(back.offsets, lists.offsets);
  ASSERT_EQ(back.hits.size(), 3u);
  EXPECT_EQ(std::memcmp(back.hits.data(), lists.hits.data(), 3 * sizeof(Hit)), 0);
}

TEST_F(RayFileTest, PointFilesRoundTrip) {
  const std::vector<Vec3f> points = {{1, 2, 3}, {-0.5f, 0, 1e30f}};
  write_points(path("p.points"), points);
  EXPECT_EQ(fs::file_size(path("p.points")), 24u);
  const std::vector<Vec3f> back = read_points(path("p.points"));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(std::memcmp(back.data(), points.data(), 24), 0);

  const std::vector<PointLocation> where = {PointLocation::kOutside, PointLocation::kOnSurface,
                                            PointLocation::kInside};
  write_locations(path("in.bin"), where);
  EXPECT_EQ(fs::file_size(path("in.bin")), 3u);
  EXPECT_EQ(read_locations(path("in.bin")), where);

  ClosestPoint c;
  c.point = {1, 2, 3};
  c.distance = 0.5f;
  c.u = 0.25f;
  c.v = 0.125f;
  c.geom_id = 1;
  c.prim_id = 42;
  const std::vector<ClosestPoint> closest = {c, ClosestPoint{}};
  write_closest(path("c.bin"), closest);
  EXPECT_EQ(fs::file_size(path("c.bin")), 64u);
  const std::vector<ClosestPoint> cb = read_closest(path("c.bin"));
  ASSERT_EQ(cb.size(), 2u);
  EXPECT_EQ(std::memcmp(cb.data(), closest.data(), 64), 0);
  EXPECT_FALSE(cb[1].found());
}

TEST_F(RayFileTest, BadPointFilesAreErrorsNamingTheFile) {
  write_bytes(path("p13.points"), 13);
  try {
    (void)read_points(path("p13.points"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p13.points"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("multiple of 12"), std::string::npos) << e.what();
  }
  std::ofstream(path("loc.bin"), std::ios::binary) << std::string("\x00\x01\x03", 3);
  try {
    (void)read_locations(path("loc.bin"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("byte 2 is 3"), std::string::npos) << e.what();
  }
  write_bytes(path("c31.bin"), 31);
  EXPECT_THROW((void)read_closest(path("c31.bin")), InputError);
}

TEST_F(RayFileTest, HitListWithALyingCountIsAnError) {
  // One ray claiming a billion hits, then 20 bytes: refused, nothing allocated.
  const uint32_t lie = 1'000'000'000u;
  {
    std::ofstream f(path("lie.bin"), std::ios::binary);
    f.write(reinterpret_cast<const char*>(&lie), 4);
    f.write(std::string(20, '\0').data(), 20);
  }
  try {
    (void)read_hit_lists(path("lie.bin"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lie.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("runs past the end"), std::string::npos) << e.what();
  }
  std::ofstream(path("short.bin"), std::ios::binary) << "ab";
  EXPECT_THROW((void)read_hit_lists(path("short.bin")), InputError);
  write_bytes(path("c3.bin"), 3);
  EXPECT_THROW((void)read_counts(path("c3.bin")), InputError);
}

TEST_F(RayFileTest, EmptyFilesAreEmptySets) {
  const std::string p = path("empty.rays");
  write_rays(p, {});
  EXPECT_EQ(fs::file_size(p), 0u);
  EXPECT_TRUE(read_rays(p).empty());
}

TEST_F(RayFileTest, WrongSizeIsInputErrorNamingThePath) {
  const std::string p = path("f.rays");
  write_bytes(p, 100);
  try {
    read_rays(p);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), p + ": size 100 is not a multiple of 32");
  }
  const std::string h = path("f.hits");
  write_bytes(h, 30);
  try {
    read_hits(h);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(h + ": size 30", 0), 0u) << e.what();
  }
}

TEST_F(RayFileTest, MissingFileAndDirectory) {
  const std::string p = path("nope.rays");
  try {
    read_rays(p);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(p + ": ", 0), 0u) << e.what();
  }
  EXPECT_THROW(read_rays(dir_.string()), InputError);  // a directory
  EXPECT_THROW(write_rays(path("missing_dir/x.rays"), std::vector<Ray>(1)), InputError);
  EXPECT_FALSE(fs::exists(path("missing_dir")));
}

}  // namespace
}  // namespace hprt
