// `hprt bench frames` end to end in --quick mode on a tiny generated mesh:
// every column in the CSV and the JSON, a row per case (wave, explode) and
// configuration including both Embree dynamic rows, the default-options row
// marked (`"default": true`, one per case) with its per-frame update letters,
// well-formed values (no timing asserted), and a bad option exits 2.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_test_support.h"

namespace fs = std::filesystem;

namespace hprt {
namespace {

using test::slurp;
using test::split_csv;

const std::vector<std::string> kColumns = {"case",
                                           "config",
                                           "default",
                                           "triangles",
                                           "threads",
                                           "frames",
                                           "build_ms",
                                           "update_ms",
                                           "update_min_ms",
                                           "update_max_ms",
                                           "update_mean_ms",
                                           "render_ms",
                                           "render_min_ms",
                                           "render_max_ms",
                                           "frame_ms",
                                           "frame_min_ms",
                                           "frame_max_ms",
                                           "frame_mean_ms",
                                           "deform_ms",
                                           "rebuilds",
                                           "updates",
                                           "sah_cost_first",
                                           "sah_cost_last",
                                           "mrays_per_s",
                                           "update_vs_embree_refit",
                                           "frame_vs_best_embree",
                                           "frame_vs_embree_matched"};
const std::vector<std::string> kBenchFramesRows = {"bvh auto (default)",
                                                   "bvh rebuild",
                                                   "bvh refit",
                                                   "bvh adaptive",
                                                   "bvh adaptive mt",
                                                   "bvh rebuild morton",
                                                   "bvh adaptive morton",
                                                   "bvh adaptive morton mt",
                                                   "embree dynamic refit",
                                                   "embree dynamic low",
                                                   "embree dynamic refit robust",
                                                   "embree dynamic low robust"};

int run_frames(const std::string& args, const fs::path& out) {
  const std::string cmd = std::string(HPRT_BINARY) + " " + args + " >" + (out / "stdout").string() +
                          " 2>" + (out / "stderr").string();
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class BenchFrames : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hprt_bench_frames_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(BenchFrames, QuickRunWritesEveryColumnAndEmbreeRows) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(
      run_frames("bench frames --quick --tris 2000 --frames 2 --threads 2 --out " + out.string(),
                 dir_),
      0)
      << slurp(dir_ / "stderr");
  const std::string md = slurp(dir_ / "stdout");
  EXPECT_NE(md.find("| wave"), std::string::npos) << md;
  EXPECT_NE(md.find("embree dynamic refit"), std::string::npos);

  // CSV: header = every column; 2 cases x 8 configurations.
  std::istringstream csv(slurp(out / "frames_frames.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(split_csv(line), kColumns);
  std::set<std::string> seen;
  int rows = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string> f = split_csv(line);
    ASSERT_EQ(f.size(), kColumns.size()) << line;
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < f.size(); ++i) row[kColumns[i]] = f[i];
    ++rows;
    seen.insert(row["case"] + "/" + row["config"]);
    EXPECT_EQ(row["triangles"], "2000");
    EXPECT_EQ(row["threads"], "2");
    EXPECT_EQ(row["frames"], "2");
    for (const char* c :
         {"update_ms", "render_ms", "frame_ms", "mrays_per_s", "update_vs_embree_refit",
          "frame_vs_best_embree", "frame_vs_embree_matched"})
      EXPECT_GT(std::stod(row[c]), 0.0) << c << " in " << line;
    EXPECT_LE(std::stod(row["update_min_ms"]), std::stod(row["update_ms"]));
    EXPECT_LE(std::stod(row["update_ms"]), std::stod(row["update_max_ms"]));
    EXPECT_LE(std::stod(row["update_min_ms"]), std::stod(row["update_mean_ms"]));
    EXPECT_LE(std::stod(row["update_mean_ms"]), std::stod(row["update_max_ms"]));
    EXPECT_LE(std::stod(row["frame_min_ms"]), std::stod(row["frame_mean_ms"]));
    EXPECT_LE(std::stod(row["frame_mean_ms"]), std::stod(row["frame_max_ms"]));
    const bool bvh = row["config"].rfind("bvh", 0) == 0;
    EXPECT_EQ(row["sah_cost_last"].empty(), !bvh) << line;
    if (row["config"].rfind("bvh rebuild", 0) == 0 ||
        row["config"].rfind("embree dynamic low", 0) == 0) {
      EXPECT_EQ(row["rebuilds"], "2");
    }
    if (row["config"] == "bvh refit" || row["config"].rfind("embree dynamic refit", 0) == 0) {
      EXPECT_EQ(row["rebuilds"], "0");
      EXPECT_EQ(row["updates"], "rr");
    }
    if (row["config"] == "bvh rebuild") {
      EXPECT_EQ(row["updates"], "ss");
    }
    if (row["config"] == "bvh rebuild morton") {
      EXPECT_EQ(row["updates"], "mm");
    }
    if (row["config"].rfind("embree dynamic low", 0) == 0) {
      EXPECT_EQ(row["updates"], "bb");
    }
    // One letter per frame; as many rebuild letters as rebuilds.
    ASSERT_EQ(row["updates"].size(), 2u) << line;
    int rebuild_letters = 0;
    for (char u : row["updates"]) {
      EXPECT_NE(std::string("rmsb").find(u), std::string::npos) << line;
      rebuild_letters += u != 'r';
    }
    EXPECT_EQ(std::to_string(rebuild_letters), row["rebuilds"]) << line;
    EXPECT_EQ(row["default"], row["config"] == "bvh auto (default)" ? "true" : "false") << line;
    // Matched numerics: against the fastest of a subset of the Embree rows,
    // so never above the ratio against the fastest of all of them.
    EXPECT_LE(std::stod(row["frame_vs_embree_matched"]), std::stod(row["frame_vs_best_embree"]));
    if (row["config"] == "embree dynamic refit") {
      EXPECT_EQ(std::stod(row["update_vs_embree_refit"]), 1.0);
    }
  }
  EXPECT_EQ(rows, 24);
  for (const char* c : {"wave", "explode"}) {
    for (const std::string& k : kBenchFramesRows)
      EXPECT_TRUE(seen.count(std::string(c) + "/" + k)) << c << "/" << k;
  }

  // JSON: the same table with every column, and the run's parameters.
  const nlohmann::json j = nlohmann::json::parse(slurp(out / "frames.json"));
  const nlohmann::json& t = j.at("tables").at("frames");
  EXPECT_EQ(t.at("columns").get<std::vector<std::string>>(), kColumns);
  ASSERT_EQ(t.at("rows").size(), 24u);
  int defaults = 0;
  for (const auto& r : t.at("rows")) {
    for (const std::string& c : kColumns) EXPECT_TRUE(r.contains(c)) << c;
    ASSERT_TRUE(r.at("default").is_boolean());
    defaults += r.at("default").get<bool>();
  }
  EXPECT_EQ(defaults, 2);  // one per case
  EXPECT_EQ(j.at("params").at("threads"), 2);
  EXPECT_EQ(j.at("params").at("triangles"), 2000);
}

TEST_F(BenchFrames, BadOptionsExit2) {
  EXPECT_EQ(run_frames("bench frames --quick --frames 0", dir_), 2);
  EXPECT_EQ(run_frames("bench frames " + (dir_ / "missing.ply").string() + " --quick", dir_), 2);
  EXPECT_NE(slurp(dir_ / "stderr").find("missing.ply"), std::string::npos);
}

}  // namespace
}  // namespace hprt
