// `hprt generate` end to end: writes a PLY that loads back with the expected
// counts; bad options exit 2 and leave no file.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "io/mesh/mesh_reader.h"

namespace fs = std::filesystem;

namespace {

class CliGenerate : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hprt_cli_generate_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs hprt with `args`, returns its exit status (stderr kept for the log).
  int hprt(const std::string& args) {
    const std::string cmd =
        std::string(HPRT_BINARY) + " " + args + " 2>" + (dir_ / "stderr.txt").string();
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string out(const std::string& name) const { return (dir_ / name).string(); }
  // Files in the directory other than the captured stderr.
  size_t files() const {
    size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_)) n += e.path().filename() != "stderr.txt";
    return n;
  }

  fs::path dir_;
};

}  // namespace

TEST_F(CliGenerate, SphereWritesLoadablePly) {
  ASSERT_EQ(hprt("generate sphere --tris 1000 -o " + out("s.ply")), 0);
  const hprt::TriangleMesh m = hprt::load_mesh(out("s.ply"));
  EXPECT_EQ(m.triangle_count(), 1280u);
  EXPECT_EQ(m.vertex_count(), 642u);
}

TEST_F(CliGenerate, EveryKindAndSubdivide) {
  for (const char* kind : {"bumpy", "torus", "soup", "slivers", "sheet", "terrain", "plane"}) {
    ASSERT_EQ(hprt(std::string("generate ") + kind + " --tris 500 --seed 9 -o " + out("k.ply")), 0)
        << kind;
    EXPECT_GE(hprt::load_mesh(out("k.ply")).triangle_count(), 500u) << kind;
  }
  ASSERT_EQ(hprt("generate sphere --tris 20 -o " + out("ico.ply")), 0);
  ASSERT_EQ(
      hprt("generate subdivide --from " + out("ico.ply") + " --tris 300 -o " + out("sub.ply")), 0);
  EXPECT_EQ(hprt::load_mesh(out("sub.ply")).triangle_count(), 320u);
}

TEST_F(CliGenerate, SameSeedSameFile) {
  ASSERT_EQ(hprt("generate soup --tris 300 --seed 5 -o " + out("a.ply")), 0);
  ASSERT_EQ(hprt("generate soup --tris 300 --seed 5 -o " + out("b.ply")), 0);
  ASSERT_EQ(hprt("generate soup --tris 300 --seed 6 -o " + out("c.ply")), 0);
  const auto a = hprt::load_mesh(out("a.ply")), b = hprt::load_mesh(out("b.ply"));
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_NE(a.positions, hprt::load_mesh(out("c.ply")).positions);
}

TEST_F(CliGenerate, BadOptionsExit2AndLeaveNoFile) {
  EXPECT_EQ(hprt("generate sphere --tris 0 -o " + out("x.ply")), 2);
  EXPECT_EQ(hprt("generate sphere --tris -4 -o " + out("x.ply")), 2);
  EXPECT_EQ(hprt("generate sphere --tris 300000000 -o " + out("x.ply")), 2);
  EXPECT_EQ(hprt("generate cube -o " + out("x.ply")), 2);
  EXPECT_EQ(hprt("generate subdivide --tris 100 -o " + out("x.ply")), 2);
  EXPECT_EQ(hprt("generate subdivide --from " + out("none.ply") + " -o " + out("x.ply")), 2);
  EXPECT_EQ(hprt("generate sphere --from " + out("none.ply") + " -o " + out("x.ply")), 2);
  EXPECT_EQ(hprt("generate sphere"), 2);  // no -o
  EXPECT_EQ(files(), 0u);
  EXPECT_EQ(hprt("generate sphere -o " + out("missing_dir/x.ply")), 2);
  EXPECT_FALSE(fs::exists(dir_ / "missing_dir"));
}
