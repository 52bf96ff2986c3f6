// `hprt rays` and `hprt trace` end to end: files, JSON fields, thread-count
// independence, and every bad input exits 2 leaving no output file behind.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/hit.h"
#include "tests/support/cli_test_support.h"

namespace fs = std::filesystem;

namespace {

using hprt::test::CliResult;
using hprt::test::slurp;

class CliTrace : public hprt::test::CliTest {
 protected:
  CliTrace() : CliTest("hprt_cli_trace_") {}
  void SetUp() override {
    CliTest::SetUp();
    std::ofstream(dir_ / "cube.obj") << hprt::test::kCubeObj;
  }
  // Files in dir_ other than the inputs: outputs and any leftover temporary.
  std::vector<std::string> outputs() const {
    std::vector<std::string> v;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n != "cube.obj" && n != "x.rays" && n != "bad.rays") v.push_back(n);
    }
    return v;
  }
  void make_rays() const {
    const CliResult r =
        run("rays " + path("cube.obj") + " --kind random -n 1000 --seed 3 -o " + path("x.rays"));
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(fs::file_size(path("x.rays")), 32000u);
  }
};

TEST_F(CliTrace, RaysThenTraceWithJson) {
  make_rays();
  const CliResult r = run("trace " + path("cube.obj") + " --backend embree --rays " +
                          path("x.rays") + " -o " + path("x.hits") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("Mrays/s"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("backend"), "embree");
  EXPECT_EQ(j.at("triangles"), 12);
  EXPECT_EQ(j.at("rays"), 1000);
  EXPECT_GE(j.at("ms").get<double>(), 0.0);
  EXPECT_GE(j.at("build_ms").get<double>(), 0.0);
  EXPECT_GE(j.at("mrays_per_s").get<double>(), 0.0);
  EXPECT_GE(j.at("threads").get<int>(), 1);
  EXPECT_EQ(j.at("output"), path("x.hits"));
  ASSERT_EQ(fs::file_size(path("x.hits")), 20000u);
  // The reported hit count is the file's, and random rays from around the
  // cube hit it often but not always.
  const std::string bytes = slurp(path("x.hits"));
  size_t hits = 0;
  for (size_t i = 0; i < 1000; ++i) {
    hprt::Hit h;
    std::memcpy(&h, bytes.data() + 20 * i, 20);
    hits += h.hit();
    if (h.hit()) {
      EXPECT_LT(h.prim_id, 12u);
      EXPECT_EQ(h.geom_id, 0u);
    }
  }
  EXPECT_EQ(j.at("hits").get<size_t>(), hits);
  EXPECT_GT(hits, 300u);
  EXPECT_LT(hits, 1000u);
}

TEST_F(CliTrace, OccludedWritesOneBytePerRay) {
  make_rays();
  const CliResult r = run("trace " + path("cube.obj") + " --backend embree --occluded --rays " +
                          path("x.rays") + " -o " + path("x.occ") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string bytes = slurp(path("x.occ"));
  ASSERT_EQ(bytes.size(), 1000u);
  size_t occluded = 0;
  for (char c : bytes) {
    ASSERT_TRUE(c == 0 || c == 1);
    occluded += c == 1;
  }
  EXPECT_EQ(nlohmann::json::parse(r.out).at("hits").get<size_t>(), occluded);
}

TEST_F(CliTrace, ThreadCountDoesNotChangeTheHitsFile) {
  make_rays();
  const std::string base =
      "trace " + path("cube.obj") + " --backend embree --rays " + path("x.rays");
  ASSERT_EQ(run(base + " --threads 1 -o " + path("a.hits")).code, 0);
  ASSERT_EQ(run(base + " --threads 2 -o " + path("b.hits")).code, 0);
  EXPECT_EQ(slurp(path("a.hits")), slurp(path("b.hits")));
}

TEST_F(CliTrace, RepeatGivesTheSameAnswersAndReportsTheMedian) {
  make_rays();
  const std::string base =
      "trace " + path("cube.obj") + " --backend bvh --threads 1 --rays " + path("x.rays");
  ASSERT_EQ(run(base + " -o " + path("once.hits")).code, 0);
  const CliResult r = run(base + " --repeat 3 --json -o " + path("thrice.hits"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(slurp(path("once.hits")), slurp(path("thrice.hits")));
  EXPECT_NE(r.err.find("(median of 3)"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("repeat").get<int>(), 3);
  EXPECT_GE(j.at("ms_first").get<double>(), 0.0);
  EXPECT_GE(j.at("ms").get<double>(), 0.0);
  // Occlusion repeats too, and a single trace says it was one.
  const CliResult o = run(base + " --occluded --repeat 2 --json -o " + path("x.occ"));
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(nlohmann::json::parse(o.out).at("repeat").get<int>(), 2);
  EXPECT_EQ(slurp(path("x.occ")).size(), 1000u);
  const CliResult one = run(base + " --json -o " + path("one.hits"));
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_EQ(one.err.find("median"), std::string::npos) << one.err;
  const nlohmann::json j1 = nlohmann::json::parse(one.out);
  EXPECT_EQ(j1.at("repeat").get<int>(), 1);
  EXPECT_EQ(j1.at("ms_first").get<double>(), j1.at("ms").get<double>());
}

TEST_F(CliTrace, BadInputExitsTwoAndLeavesNoOutput) {
  make_rays();
  std::ofstream(path("bad.rays"), std::ios::binary) << std::string(100, '\0');
  const std::string out = " -o " + path("out.hits");
  const std::string good = path("cube.obj") + " --backend embree --rays " + path("x.rays");
  struct Case {
    const char* what;
    std::string args;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"rays file of size 100",
       "trace " + path("cube.obj") + " --backend embree --rays " + path("bad.rays") + out,
       "size 100 is not a multiple of 32"},
      {"missing scene",
       "trace " + path("nope.obj") + " --backend embree --rays " + path("x.rays") + out,
       "nope.obj"},
      {"missing rays file",
       "trace " + path("cube.obj") + " --backend embree --rays " + path("nope.rays") + out,
       "nope.rays"},
      {"unknown backend",
       "trace " + path("cube.obj") + " --backend optix --rays " + path("x.rays") + out, "optix"},
      {"missing output directory", "trace " + good + " -o " + path("missing_dir") + "/out.hits",
       "missing_dir"},
      {"negative threads", "trace " + good + " --threads -1" + out, "threads"},
      {"zero repeats", "trace " + good + " --repeat 0" + out, "repeat"},
      {"too many repeats", "trace " + good + " --repeat 1001" + out, "repeat"},
      {"fractional repeats", "trace " + good + " --repeat 1.5" + out, "repeat"},
      {"too many rays",
       "rays " + path("cube.obj") + " --kind random -n 1000000000000 -o " + path("out.rays"),
       "too many rays"},
      {"too many rays (exponent)",
       "rays " + path("cube.obj") + " --kind random -n 1e12 -o " + path("out.rays"),
       "too many rays"},
      {"fractional rays",
       "rays " + path("cube.obj") + " --kind random -n 2.5 -o " + path("out.rays"), "whole number"},
      {"zero rays", "rays " + path("cube.obj") + " --kind random -n 0 -o " + path("out.rays"),
       "-n"},
      {"unknown kind", "rays " + path("cube.obj") + " --kind diagonal -n 10 -o " + path("out.rays"),
       "diagonal"},
      {"rays into missing directory",
       "rays " + path("cube.obj") + " --kind random -n 10 -o " + path("missing_dir") + "/x.rays",
       "missing_dir"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const CliResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("hprt: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_TRUE(outputs().empty()) << outputs().front();
  }
}

TEST_F(CliTrace, ShadowRaysThroughTheDefaultCamera) {
  const CliResult r =
      run("rays " + path("cube.obj") + " --kind shadow -n 5e2 -o " + path("s.rays"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(fs::file_size(path("s.rays")), 500u * 32u);
  // The same seed gives the same file.
  ASSERT_EQ(run("rays " + path("cube.obj") + " --kind shadow -n 500 -o " + path("t.rays")).code, 0);
  EXPECT_EQ(slurp(path("s.rays")), slurp(path("t.rays")));
}

}  // namespace
