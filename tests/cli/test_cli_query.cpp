// `hprt query` end to end: count and all files (sizes, agreement with each
// other and with the cube's geometry), inside and closest files for points
// on and around the cube, JSON fields, Embree's answers, and bad input
// exiting 2 without an output file.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/ray.h"
#include "io/rays/ray_file.h"
#include "tests/support/cli_test_support.h"

namespace fs = std::filesystem;

namespace {

using hprt::test::CliResult;

class CliQuery : public hprt::test::CliTest {
 protected:
  CliQuery() : CliTest("hprt_cli_query_") {}
  void SetUp() override {
    CliTest::SetUp();
    std::ofstream(dir_ / "cube.obj") << hprt::test::kCubeObj;
    // From the centre (one crossing, also exactly through the face
    // diagonals and a corner), from outside through the cube (two), beside
    // it (none).
    std::vector<hprt::Ray> rays;
    auto add = [&](hprt::Vec3f o, hprt::Vec3f d) {
      hprt::Ray r;
      r.org = o;
      r.dir = d;
      rays.push_back(r);
    };
    add({0, 0, 0}, {0.3f, 0.2f, 1});
    add({0, 0, 0}, {1, 1, 0.5f});     // through the diagonal of the face x = 1? no: an edge
    add({0, 0, 0}, {1, 1, 1});        // a corner
    add({0, 0, 0}, {0.5f, 0.5f, 1});  // the diagonal of the face z = 1
    add({-5, 0.1f, 0.2f}, {1, 0, 0});
    add({-5, 0, 0}, {1, 0, 0});  // through the face diagonals' crossing at (-1, 0, 0)
    add({-5, 3, 0}, {1, 0, 0});
    hprt::write_rays(path("x.rays"), rays);
  }
};

TEST_F(CliQuery, CountAndAllAgree) {
  const CliResult c = run("query " + path("cube.obj") + " --rays " + path("x.rays") +
                          " --kind count -o " + path("c.bin") + " --json");
  ASSERT_EQ(c.code, 0) << c.err;
  const std::vector<uint32_t> counts = hprt::read_counts(path("c.bin"));
  EXPECT_EQ(counts, (std::vector<uint32_t>{1, 1, 1, 1, 2, 2, 0}));
  const nlohmann::json j = nlohmann::json::parse(c.out);
  EXPECT_EQ(j.at("kind"), "count");
  EXPECT_EQ(j.at("rays"), 7);
  EXPECT_EQ(j.at("hits"), 8);

  const CliResult a = run("query " + path("cube.obj") + " --rays " + path("x.rays") +
                          " --kind all --max-hits 1 -o " + path("a.bin") + " --json");
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_NE(a.err.find("more than --max-hits 1"), std::string::npos) << a.err;
  const hprt::HitLists lists = hprt::read_hit_lists(path("a.bin"));
  ASSERT_EQ(lists.rays(), 7u);
  EXPECT_EQ(lists.count(4), 1u);
  EXPECT_FLOAT_EQ(lists.begin(4)[0].t, 4.0f);  // the near face, x = -1
  EXPECT_EQ(nlohmann::json::parse(a.out).at("truncated_rays"), 2);
}

TEST_F(CliQuery, EmbreeAnswersToo) {
  const CliResult c = run("query " + path("cube.obj") + " --backend embree --rays " +
                          path("x.rays") + " --kind count -o " + path("c.bin"));
  ASSERT_EQ(c.code, 0) << c.err;
  const std::vector<uint32_t> counts = hprt::read_counts(path("c.bin"));
  ASSERT_EQ(counts.size(), 7u);
  EXPECT_EQ(counts[0], 1u);  // a generic ray: the same crossing
  EXPECT_EQ(counts[6], 0u);
}

// The cube [-1, 1]^3: a point inside, one on a face, one on an edge, one
// exactly on a vertex, one outside; closest points on its faces.
TEST_F(CliQuery, InsideAndClosestOnTheCube) {
  const std::vector<hprt::Vec3f> points = {
      {0.2f, 0.1f, 0.0f}, {1.0f, 0.5f, 0.25f}, {1.0f, 1.0f, 0.0f}, {-1, -1, -1}, {3, 0, 0}};
  hprt::write_points(path("p.points"), points);
  for (const char* backend : {"bvh", "embree"}) {
    SCOPED_TRACE(backend);
    const CliResult in = run("query " + path("cube.obj") + " --backend " + backend + " --points " +
                             path("p.points") + " --kind inside -o " + path("in.bin") + " --json");
    ASSERT_EQ(in.code, 0) << in.err;
    const std::vector<hprt::PointLocation> where = hprt::read_locations(path("in.bin"));
    using L = hprt::PointLocation;
    EXPECT_EQ(where, (std::vector<L>{L::kInside, L::kOnSurface, L::kOnSurface, L::kOnSurface,
                                     L::kOutside}));
    const nlohmann::json j = nlohmann::json::parse(in.out);
    EXPECT_EQ(j.at("points"), 5);
    EXPECT_EQ(j.at("inside"), 1);
    EXPECT_EQ(j.at("on_surface"), 3);

    const CliResult c = run("query " + path("cube.obj") + " --backend " + backend + " --points " +
                            path("p.points") + " --kind closest --max-distance 1.5 -o " +
                            path("c.bin") + " --json");
    ASSERT_EQ(c.code, 0) << c.err;
    const std::vector<hprt::ClosestPoint> near = hprt::read_closest(path("c.bin"));
    ASSERT_EQ(near.size(), 5u);
    EXPECT_FLOAT_EQ(near[0].distance, 0.8f);  // the face x = 1
    EXPECT_FLOAT_EQ(near[0].point.x, 1.0f);
    EXPECT_EQ(near[1].distance, 0.0f);
    EXPECT_EQ(near[3].distance, 0.0f);
    EXPECT_FALSE(near[4].found());  // 2 away, beyond --max-distance 1.5
    EXPECT_EQ(near[4].prim_id, 0xFFFFFFFFu);
    EXPECT_EQ(nlohmann::json::parse(c.out).at("found"), 4);
  }
}

TEST_F(CliQuery, PointKindsNeedPointsAndRayKindsRays) {
  hprt::write_points(path("p.points"), std::vector<hprt::Vec3f>{{0, 0, 0}});
  const CliResult a = run("query " + path("cube.obj") + " --rays " + path("x.rays") +
                          " --kind inside -o " + path("out.bin"));
  EXPECT_EQ(a.code, 2);
  EXPECT_NE(a.err.find("--points"), std::string::npos) << a.err;
  const CliResult b = run("query " + path("cube.obj") + " --points " + path("p.points") +
                          " --kind count -o " + path("out.bin"));
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(b.err.find("--rays"), std::string::npos) << b.err;
  std::ofstream(dir_ / "bad.points") << "0123456789";
  const CliResult c = run("query " + path("cube.obj") + " --points " + path("bad.points") +
                          " --kind closest -o " + path("out.bin"));
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("bad.points"), std::string::npos) << c.err;
  const CliResult d = run("query " + path("cube.obj") + " --points " + path("p.points") +
                          " --kind closest --max-distance -1 -o " + path("out.bin"));
  EXPECT_EQ(d.code, 2);
  EXPECT_NE(d.err.find("--max-distance: must be a number >= 0, got -1"), std::string::npos)
      << d.err;
  EXPECT_LT(d.err.size(), 200u) << d.err;  // one short line
  const CliResult nan = run("query " + path("cube.obj") + " --points " + path("p.points") +
                            " --kind closest --max-distance nan -o " + path("out.bin"));
  EXPECT_EQ(nan.code, 2);
  EXPECT_NE(nan.err.find("must be a number >= 0, got nan"), std::string::npos) << nan.err;
  const CliResult e = run("query " + path("cube.obj") + " --isect mt --points " + path("p.points") +
                          " --kind inside -o " + path("out.bin"));
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(e.err.find("watertight"), std::string::npos) << e.err;
  EXPECT_FALSE(fs::exists(path("out.bin")));
}

TEST_F(CliQuery, BadInputExits2WithoutOutput) {
  std::ofstream(dir_ / "bad.rays") << "0123456789";  // not a whole number of rays
  const CliResult r = run("query " + path("cube.obj") + " --rays " + path("bad.rays") +
                          " --kind count -o " + path("out.bin"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.rays"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("out.bin")));
  const CliResult k = run("query " + path("cube.obj") + " --rays " + path("x.rays") +
                          " --kind nearest -o " + path("out.bin"));
  EXPECT_EQ(k.code, 2);
  EXPECT_FALSE(fs::exists(path("out.bin")));
}

}  // namespace
