// `hprt rays` and `hprt trace` end to end: files, JSON fields, thread-count
// independence, and every bad input exits 2 leaving no output file behind.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "core/hit.h"

namespace fs = std::filesystem;

namespace {

struct Result {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

class CliTrace : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("hprt_cli_trace_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A closed unit cube, 12 triangles, as OBJ text.
    std::ofstream(dir_ / "cube.obj") << "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                                        "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                                        "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\n"
                                        "f 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n"
                                        "f 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) const {
    const std::string cmd = std::string(HPRT_BINARY) + " " + args + " >" +
                            (dir_ / "stdout.txt").string() + " 2>" + (dir_ / "stderr.txt").string();
    const int status = std::system(cmd.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(dir_ / "stdout.txt");
    r.err = slurp(dir_ / "stderr.txt");
    fs::remove(dir_ / "stdout.txt");
    fs::remove(dir_ / "stderr.txt");
    return r;
  }
  std::string p(const char* name) const { return (dir_ / name).string(); }
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
    const Result r =
        run("rays " + p("cube.obj") + " --kind random -n 1000 --seed 3 -o " + p("x.rays"));
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(fs::file_size(p("x.rays")), 32000u);
  }
  fs::path dir_;
};

TEST_F(CliTrace, RaysThenTraceWithJson) {
  make_rays();
  const Result r = run("trace " + p("cube.obj") + " --backend embree --rays " + p("x.rays") +
                       " -o " + p("x.hits") + " --json");
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
  EXPECT_EQ(j.at("output"), p("x.hits"));
  ASSERT_EQ(fs::file_size(p("x.hits")), 20000u);
  // The reported hit count is the file's, and random rays from around the
  // cube hit it often but not always.
  const std::string bytes = slurp(p("x.hits"));
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
  const Result r = run("trace " + p("cube.obj") + " --backend embree --occluded --rays " +
                       p("x.rays") + " -o " + p("x.occ") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string bytes = slurp(p("x.occ"));
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
  const std::string base = "trace " + p("cube.obj") + " --backend embree --rays " + p("x.rays");
  ASSERT_EQ(run(base + " --threads 1 -o " + p("a.hits")).code, 0);
  ASSERT_EQ(run(base + " --threads 2 -o " + p("b.hits")).code, 0);
  EXPECT_EQ(slurp(p("a.hits")), slurp(p("b.hits")));
}

TEST_F(CliTrace, BadInputExitsTwoAndLeavesNoOutput) {
  make_rays();
  std::ofstream(p("bad.rays"), std::ios::binary) << std::string(100, '\0');
  const std::string out = " -o " + p("out.hits");
  const std::string good = p("cube.obj") + " --backend embree --rays " + p("x.rays");
  struct Case {
    const char* what;
    std::string args;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"rays file of size 100",
       "trace " + p("cube.obj") + " --backend embree --rays " + p("bad.rays") + out,
       "size 100 is not a multiple of 32"},
      {"missing scene", "trace " + p("nope.obj") + " --backend embree --rays " + p("x.rays") + out,
       "nope.obj"},
      {"missing rays file",
       "trace " + p("cube.obj") + " --backend embree --rays " + p("nope.rays") + out, "nope.rays"},
      {"unknown backend", "trace " + p("cube.obj") + " --backend optix --rays " + p("x.rays") + out,
       "optix"},
      {"missing output directory", "trace " + good + " -o " + p("missing_dir") + "/out.hits",
       "missing_dir"},
      {"negative threads", "trace " + good + " --threads -1" + out, "threads"},
      {"too many rays",
       "rays " + p("cube.obj") + " --kind random -n 1000000000000 -o " + p("out.rays"),
       "too many rays"},
      {"too many rays (exponent)",
       "rays " + p("cube.obj") + " --kind random -n 1e12 -o " + p("out.rays"), "too many rays"},
      {"fractional rays", "rays " + p("cube.obj") + " --kind random -n 2.5 -o " + p("out.rays"),
       "whole number"},
      {"zero rays", "rays " + p("cube.obj") + " --kind random -n 0 -o " + p("out.rays"), "-n"},
      {"unknown kind", "rays " + p("cube.obj") + " --kind diagonal -n 10 -o " + p("out.rays"),
       "diagonal"},
      {"rays into missing directory",
       "rays " + p("cube.obj") + " --kind random -n 10 -o " + p("missing_dir") + "/x.rays",
       "missing_dir"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const Result r = run(c.args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("hprt: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_TRUE(outputs().empty()) << outputs().front();
  }
}

TEST_F(CliTrace, ShadowRaysThroughTheDefaultCamera) {
  const Result r = run("rays " + p("cube.obj") + " --kind shadow -n 5e2 -o " + p("s.rays"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(fs::file_size(p("s.rays")), 500u * 32u);
  // The same seed gives the same file.
  ASSERT_EQ(run("rays " + p("cube.obj") + " --kind shadow -n 500 -o " + p("t.rays")).code, 0);
  EXPECT_EQ(slurp(p("s.rays")), slurp(p("t.rays")));
}

}  // namespace
