// `hprt validate rays` end to end: exit 0 and the JSON fields on a small OBJ
// written by the test; exit 2 for a missing rays file, a rays file of the
// wrong size and neither --rays nor --kind.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct CmdResult {
  int code;
  std::string out;
};

CmdResult run(const std::string& args) {
  const std::string cmd = std::string(HPRT_BINARY) + " " + args + " 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WEXITSTATUS(status), out};
}

fs::path temp_dir() {
  const fs::path d =
      fs::temp_directory_path() / ("hprt_cli_validate_rays_" + std::to_string(getpid()));
  fs::create_directories(d);
  return d;
}

// An octahedron: closed, 6 vertices, 8 faces.
std::string write_obj(const fs::path& dir) {
  const fs::path p = dir / "octa.obj";
  std::ofstream f(p);
  f << "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
       "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
  return p.string();
}

TEST(CliValidateRays, JsonOnSmallScene) {
  const fs::path d = temp_dir();
  const std::string obj = write_obj(d);
  for (const char* kind : {"random", "edge-probe", "primary"}) {
    const CmdResult r =
        run("validate rays " + obj + " --kind " + kind + " -n 500 --threads 2 --json " +
            "--mismatches " + (d / "mm.rays").string());
    ASSERT_EQ(r.code, 0) << kind << ": " << r.out;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["rays"], 500);
    EXPECT_EQ(j["kind"], kind);
    for (const char* k : {"agree", "ties", "mismatches", "bvh_right", "embree_right", "both_wrong",
                          "max_rel_t_error", "bvh_config", "embree_config", "mismatches_file"})
      EXPECT_TRUE(j.contains(k)) << k;
    EXPECT_EQ(j["bvh_wrong"], 0);
    EXPECT_EQ(j["agree"].get<int>() + j["ties"].get<int>() + j["mismatches"].get<int>(), 500);
    if (j["mismatches"] == 0) {
      EXPECT_TRUE(j["mismatches_file"].is_null());
    }
  }
  // Replaying a rays file written by `hprt rays`.
  ASSERT_EQ(run("rays " + obj + " --kind random -n 300 -o " + (d / "in.rays").string()).code, 0);
  const CmdResult r =
      run("validate rays " + obj + " --rays " + (d / "in.rays").string() + " --json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(nlohmann::json::parse(r.out)["rays"], 300);
  fs::remove_all(d);
}

TEST(CliValidateRays, BadInputExits2) {
  const fs::path d = temp_dir();
  const std::string obj = write_obj(d);
  EXPECT_EQ(run("validate rays " + obj + " --rays " + (d / "missing.rays").string()).code, 2);
  {
    std::ofstream f(d / "bad.rays", std::ios::binary);
    f << "0123456789";  // not a multiple of 32 bytes
  }
  EXPECT_EQ(run("validate rays " + obj + " --rays " + (d / "bad.rays").string()).code, 2);
  EXPECT_EQ(run("validate rays " + obj).code, 2);                     // neither --rays nor --kind
  EXPECT_EQ(run("validate rays " + obj + " --kind random").code, 2);  // no -n
  EXPECT_EQ(run("validate rays " + (d / "none.obj").string() + " --kind random -n 5").code, 2);
  fs::remove_all(d);
}

}  // namespace
