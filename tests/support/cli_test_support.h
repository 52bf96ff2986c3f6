// Scaffolding for the tests that run the hprt binary: a fresh directory per
// test, running HPRT_BINARY (defined for every test by tests/CMakeLists.txt)
// with its output captured, and whole-file reads.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace hprt::test {

struct CliResult {
  int code = -1;
  std::string out, err;
};

// The closed cube [-1, 1]^3 as 12 triangles, OBJ text.
inline constexpr const char* kCubeObj =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
    "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\n"
    "f 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n"
    "f 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// The fields of one CSV line (no quoting; a trailing comma ends an empty field).
inline std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) out.push_back(field);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

// Runs `prefix HPRT_BINARY args` through the shell, in `cwd` if given;
// `prefix` is shell text such as a ulimit. stdout and stderr go through the
// files <capture>.stdout and <capture>.stderr, beside the directory `capture`
// rather than in it, and are removed afterwards.
inline CliResult run_hprt(const std::string& args, const std::filesystem::path& capture,
                          const std::filesystem::path& cwd = {}, const std::string& prefix = "") {
  const std::filesystem::path out = capture.string() + ".stdout";
  const std::filesystem::path err = capture.string() + ".stderr";
  std::string cmd = cwd.empty() ? "" : "cd '" + cwd.string() + "' && ";
  cmd += prefix + HPRT_BINARY + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

// A fixture giving each test the empty directory <temp>/<prefix><test name>,
// removed after the test.
class TempDirTest : public ::testing::Test {
 protected:
  explicit TempDirTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

class CliTest : public TempDirTest {
 protected:
  using TempDirTest::TempDirTest;
  CliResult run(const std::string& args, const std::string& prefix = "") const {
    return run_hprt(args, dir_, {}, prefix);
  }
};

}  // namespace hprt::test
