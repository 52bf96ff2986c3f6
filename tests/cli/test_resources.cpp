// Memory bounds, scaled down from the README's "Resources" figures (10M
// triangles, 4K render): `hprt build --json` reports peak memory and bytes per
// triangle that match the process's real peak RSS (wait4) and stay under
// kBuildBytesPerTri x triangles + kBaseBytes; a render stays under
// kRenderBytesPerPixel x pixels + kBaseBytes. Nothing is timed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/cli_test_support.h"

extern char** environ;

namespace fs = std::filesystem;

namespace hprt {
namespace {

// The README's bounds (peak RSS of the whole process, input mesh included).
constexpr double kBuildBytesPerTri = 300.0;
constexpr double kRenderBytesPerPixel = 64.0;
constexpr double kBaseBytes = 256.0 * 1024 * 1024;  // libraries, TBB/Embree arenas, I/O buffers

struct ProcessRun {
  int code = -1;
  long max_rss_bytes = 0;
  std::string out;
};

// Runs hprt with stdout to a file; returns its exit code and peak RSS.
ProcessRun run_hprt(const std::vector<std::string>& args, const fs::path& dir) {
  std::vector<std::string> all = {HPRT_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string out = (dir / "stdout.txt").string();
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  ProcessRun r;
  const int rc = posix_spawn(&pid, HPRT_BINARY, &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return r;
  int status = 0;
  rusage ru{};
  if (wait4(pid, &status, 0, &ru) != pid) return r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.max_rss_bytes = ru.ru_maxrss * 1024L;
  r.out = test::slurp(out);
  return r;
}

class Resources : public test::TempDirTest {
 protected:
  Resources() : TempDirTest("hprt_resources_") {}
};

TEST_F(Resources, BuildOfOneMillionTrianglesStaysInBound) {
  const std::string mesh = (dir_ / "m.ply").string();
  ASSERT_EQ(run_hprt({"generate", "sphere", "--tris", "1000000", "-o", mesh}, dir_).code, 0);
  const ProcessRun b = run_hprt({"build", mesh, "--threads", "2", "--json"}, dir_);
  ASSERT_EQ(b.code, 0);
  const auto j = nlohmann::json::parse(b.out);
  const double tris = j.at("triangles").get<double>();
  ASSERT_GT(tris, 999999.0);
  const double peak = j.at("peak_memory_bytes").get<double>();
  const double bytes_per_tri = j.at("bytes_per_triangle").get<double>();
  // The reported peak is the process's: it agrees with what wait4 measured.
  EXPECT_GT(peak, 0.5 * double(b.max_rss_bytes));
  EXPECT_LT(peak, 1.5 * double(b.max_rss_bytes));
  // bytes_per_triangle is the acceleration structure's own size per triangle.
  EXPECT_NEAR(bytes_per_tri, j.at("memory_bytes").get<double>() / tris, 1e-6 * bytes_per_tri);
  EXPECT_GT(bytes_per_tri, 32.0);  // at least the triangle data itself
  EXPECT_LT(bytes_per_tri, 200.0);
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)  // shadow memory
  EXPECT_LT(double(b.max_rss_bytes), kBuildBytesPerTri * tris + kBaseBytes)
      << "peak RSS " << b.max_rss_bytes << " bytes for " << tris << " triangles";
#endif
}

TEST_F(Resources, RenderStaysInBound) {
  const std::string scene = std::string(HPRT_SOURCE_DIR) + "/data/scenes/default.json";
  const int w = 1920, h = 1080;
  const ProcessRun r =
      run_hprt({"render", scene, "--width", std::to_string(w), "--height", std::to_string(h),
                "--threads", "2", "-o", (dir_ / "a.exr").string()},
               dir_);
  ASSERT_EQ(r.code, 0);
  EXPECT_TRUE(fs::exists(dir_ / "a.exr"));
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  EXPECT_LT(double(r.max_rss_bytes), kRenderBytesPerPixel * w * h + kBaseBytes)
      << "peak RSS " << r.max_rss_bytes << " bytes for " << w << "x" << h;
#endif
}

}  // namespace
}  // namespace hprt
