// `hprt validate query` and `hprt points` end to end: the bvh backend passes
// (exit 0) on every query and point kind of a generated torus, Embree as the
// backend under test is caught (exit 1, disputed points written), and bad
// arguments exit 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/rays/ray_file.h"
#include "tests/support/cli_test_support.h"

namespace fs = std::filesystem;

namespace {

using hprt::test::CliResult;

class CliValidateQuery : public hprt::test::CliTest {
 protected:
  CliValidateQuery() : CliTest("hprt_cli_validate_query_") {}
  void SetUp() override {
    CliTest::SetUp();
    const CliResult g = run("generate torus --tris 2000 -o " + path("torus.ply"));
    ASSERT_EQ(g.code, 0) << g.err;
  }
};

TEST_F(CliValidateQuery, BvhPassesEveryQueryAndKind) {
  for (const char* q : {"inside", "closest"})
    for (const char* kind : {"random", "near", "hard"}) {
      SCOPED_TRACE(std::string(q) + "/" + kind);
      const CliResult r =
          run("validate query " + path("torus.ply") + " --query " + q + " --kind " + kind +
              " -n 2000 --threads 2 --json --mismatches " + path("mm.points"));
      ASSERT_EQ(r.code, 0) << r.err;
      const nlohmann::json j = nlohmann::json::parse(r.out);
      EXPECT_EQ(j.at("queries"), 2000);
      EXPECT_EQ(j.at("backend_wrong"), 0);
      EXPECT_EQ(j.at("pass"), true);
      EXPECT_EQ(j.at("unjudged"), 0);
    }
  for (const char* kind : {"random", "vertex-probe", "edge-probe", "axis"}) {
    SCOPED_TRACE(kind);
    const CliResult r = run("validate query " + path("torus.ply") + " --query count --kind " +
                            kind + " -n 2000 --threads 2 --json --mismatches " + path("mm.rays"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out).at("backend_wrong"), 0);
  }
}

// Points within float rounding of the surface: Embree's parity misses some,
// the judge says so, and the disputed points replay through `hprt query`.
TEST_F(CliValidateQuery, EmbreeUnderTestIsCaughtOnNearPoints) {
  const CliResult p =
      run("points " + path("torus.ply") + " --kind near -n 20000 -o " + path("near.points"));
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_EQ(hprt::read_points(path("near.points")).size(), 20000u);
  const CliResult r = run("validate query " + path("torus.ply") +
                          " --query inside --backend embree --reference bvh --points " +
                          path("near.points") + " --json --mismatches " + path("mm.points"));
  EXPECT_EQ(r.code, 1) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j.at("backend_wrong").get<int>(), 0);
  EXPECT_EQ(j.at("reference_right"), j.at("backend_wrong"));
  EXPECT_NE(r.err.find("FAIL"), std::string::npos) << r.err;
  const auto disputed = hprt::read_points(path("mm.points"));
  EXPECT_EQ(disputed.size(), j.at("mismatches").get<size_t>());
  const CliResult q = run("query " + path("torus.ply") + " --points " + path("mm.points") +
                          " --kind inside -o " + path("in.bin"));
  EXPECT_EQ(q.code, 0) << q.err;
}

TEST_F(CliValidateQuery, BadArgumentsExit2) {
  const std::string t = path("torus.ply");
  EXPECT_EQ(run("validate query " + t + " --query inside").code, 2);              // no points
  EXPECT_EQ(run("validate query " + t + " --query inside --kind near").code, 2);  // no -n
  EXPECT_EQ(run("validate query " + t + " --query count --kind near -n 5").code, 2);
  EXPECT_EQ(run("validate query " + t + " --query inside --kind primary -n 5").code, 2);
  EXPECT_EQ(run("validate query " + t + " --query nearest --kind near -n 5").code, 2);
  const CliResult m =
      run("validate query " + t + " --query closest --points " + path("missing.points"));
  EXPECT_EQ(m.code, 2);
  EXPECT_NE(m.err.find("missing.points"), std::string::npos) << m.err;
  EXPECT_EQ(run("points " + t + " --kind near -n 0 -o " + path("p.points")).code, 2);
  EXPECT_EQ(run("points " + t + " --kind lattice -n 5 -o " + path("p.points")).code, 2);
  EXPECT_FALSE(fs::exists(path("p.points")));
}

}  // namespace
