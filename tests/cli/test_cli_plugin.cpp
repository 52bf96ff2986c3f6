// `--backend plugin:PATH.so[:OPTIONS]` end to end in every command that
// takes a backend, with the test plugins of tests/plugins: a correct plugin
// traces, renders (stills and frames), validates against Embree (and as the
// reference), and runs in each bench; a lying one is found wrong by `validate
// rays` with its malformed answers counted; a broken one exits 2 with one
// line naming the file and the problem.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>

#include "tests/support/cli_test_support.h"

namespace hprt::test {
namespace {

class CliPlugin : public TempDirTest {
 protected:
  CliPlugin() : TempDirTest("hprt_cli_plugin_") {}
  void SetUp() override {
    TempDirTest::SetUp();
    mesh_ = path("sphere.ply");
    ASSERT_EQ(run("generate sphere --tris 2000 -o " + mesh_).code, 0);
  }
  CliResult run(const std::string& args) { return run_hprt(args, dir_ / "run"); }
  std::string mesh_;
};

const std::string kGood = std::string("plugin:") + HPRT_TEST_PLUGIN_GOOD;
const std::string kLies = std::string("plugin:") + HPRT_TEST_PLUGIN_MALFORMED;

TEST_F(CliPlugin, TraceAndRender) {
  ASSERT_EQ(run("rays " + mesh_ + " --kind random -n 3000 -o " + path("r.rays")).code, 0);
  for (const std::string& b : {std::string("bvh"), kGood}) {
    const CliResult r = run("trace " + mesh_ + " --rays " + path("r.rays") + " --backend " + b +
                            " --json -o " + path("h.hits"));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find(b == "bvh" ? "\"bvh/" : "\"plugin/test\""), std::string::npos) << r.out;
  }
  const CliResult lies = run("trace " + mesh_ + " --rays " + path("r.rays") + " --backend " +
                             kLies + " -o " + path("l.hits"));
  EXPECT_EQ(lies.code, 0);
  EXPECT_NE(lies.err.find("malformed answers"), std::string::npos) << lies.err;
  EXPECT_EQ(run("render " + mesh_ + " --width 48 --backend " + kGood + " -o " + path("s.png")).code,
            0);
  // Every command that traces through a lying plugin says so, on one line.
  for (const std::string& cmd :
       {"render " + mesh_ + " --width 48 --json -o " + path("l.png") + " --backend " + kLies,
        "rays " + mesh_ + " --kind shadow -n 2000 -o " + path("l.rays") + " --backend " + kLies,
        "bench trace " + mesh_ + " --quick --no-suite --rays 500 --threads 1 --repeat 1 --out " +
            path("bench") + " --backend " + kLies}) {
    const CliResult r = run(cmd);
    EXPECT_EQ(r.code, 0) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find(": warning: "), std::string::npos) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find("plugin/test gave "), std::string::npos) << cmd << ": " << r.err;
  }
  EXPECT_NE(slurp(path("bench") + "/trace.json").find("\"bvh_malformed\""), std::string::npos);
  // A query the plugin ABI has no call for names the option to change.
  const CliResult count = run("query " + mesh_ + " --rays " + path("r.rays") + " --kind count -o " +
                              path("c.counts") + " --backend " + kGood);
  EXPECT_EQ(count.code, 2);
  EXPECT_NE(count.err.find("--backend: plugin/test does not answer count queries"),
            std::string::npos)
      << count.err;
  const std::string wave = std::string(HPRT_SOURCE_DIR) + "/data/scenes/anim_wave.json";
  const CliResult frames = run("render " + wave + " --width 32 --frames 0:2 --backend " + kGood +
                               " -o " + path("f_%02d.png"));
  EXPECT_EQ(frames.code, 0) << frames.err;
  EXPECT_TRUE(std::filesystem::exists(path("f_01.png")));
}

TEST_F(CliPlugin, ValidateRaysEitherSide) {
  const std::string base = "validate rays " + mesh_ + " -n 2000 --mismatches " + path("m.rays");
  for (const char* kind : {"random", "edge-probe"}) {
    const CliResult r = run(base + " --kind " + kind + " --backend " + kGood);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("plugin/test vs embree/medium"), std::string::npos) << r.err;
  }
  EXPECT_EQ(run(base + " --kind random --backend bvh --reference " + kGood).code, 0);
  EXPECT_EQ(run(base + " --kind shadow --occluded --backend " + kGood).code, 0);
  const CliResult lies = run(base + " --kind primary --backend " + kLies + " --json");
  EXPECT_EQ(lies.code, 1) << lies.err;
  EXPECT_NE(lies.err.find("malformed (backend)"), std::string::npos) << lies.err;
  EXPECT_NE(lies.out.find("\"bvh_malformed\""), std::string::npos);
  const CliResult occ = run(base + " --kind random --occluded --backend " + kLies);
  EXPECT_EQ(occ.code, 1) << occ.err;
}

TEST_F(CliPlugin, BrokenPluginsExitTwoWithOneLine) {
  const std::pair<std::string, std::string> cases[] = {
      {"plugin:" + path("missing.so"), "missing.so: plugin file not found"},
      {"plugin:" + path("fifo.so"), "fifo.so: not a regular file"},  // dlopen would block
      {std::string("plugin:") + HPRT_TEST_PLUGIN_BAD_ABI, "plugin ABI version 2"},
      {std::string("plugin:") + HPRT_TEST_PLUGIN_NULL_INTERSECT, "NULL 'intersect'"},
      {std::string("plugin:") + HPRT_TEST_PLUGIN_NO_ENTRY, "no hprt_plugin_entry symbol"},
      {std::string("plugin:") + HPRT_TEST_PLUGIN_CREATE_FAILS, "create failed"},
      {std::string("plugin:") + HPRT_TEST_PLUGIN_BUILD_FAILS, "build failed"},
      {kGood + ":turbo=1", "unknown option"},
      {"plugin:", "names no plugin file"},
      {"optix", "unknown backend"},
  };
  ASSERT_EQ(::mkfifo(path("fifo.so").c_str(), 0600), 0);
  for (const auto& [spec, problem] : cases) {
    for (const std::string& cmd :
         {"validate rays " + mesh_ + " --kind random -n 10 --backend ",
          "render " + mesh_ + " --width 8 -o " + path("x.png") + " --backend "}) {
      const CliResult r = run(cmd + "'" + spec + "'");
      EXPECT_EQ(r.code, 2) << spec << ": " << r.err;
      EXPECT_NE(r.err.find(problem), std::string::npos) << spec << ": " << r.err;
      EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;  // one line
    }
  }
  EXPECT_FALSE(std::filesystem::exists(path("x.png")));
}

TEST_F(CliPlugin, EveryBenchTakesIt) {
  const std::string b = " --quick --threads 1 --repeat 1 --backend " + kGood;
  const CliResult trace = run("bench trace " + mesh_ + " --no-suite --rays 500" + b);
  ASSERT_EQ(trace.code, 0) << trace.err;
  EXPECT_NE(trace.out.find(kGood), std::string::npos);
  const CliResult build = run("bench build " + mesh_ + b);
  ASSERT_EQ(build.code, 0) << build.err;
  EXPECT_NE(build.out.find("backend:" + kGood), std::string::npos);
  const CliResult frames = run("bench frames " + mesh_ + " --frames 1" + b);
  ASSERT_EQ(frames.code, 0) << frames.err;
  EXPECT_NE(frames.out.find(kGood), std::string::npos);
  const CliResult frontier =
      run("bench frontier " + mesh_ + " --hard-rays 20 --trace-rays 200" + b);
  ASSERT_EQ(frontier.code, 0) << frontier.err;
  EXPECT_NE(frontier.out.find(kGood), std::string::npos);
}

}  // namespace
}  // namespace hprt::test
