// `hprt query` end to end: count and all files (sizes, agreement with each
// other and with the cube's geometry), JSON fields, Embree's answers, and
// bad input exiting 2 without an output file.
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
