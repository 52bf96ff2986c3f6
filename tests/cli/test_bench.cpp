// `hprt bench build|trace|frontier` end to end in --quick mode on tiny
// generated meshes and scenes: every column is in the CSV and JSON, the
// Embree rows are there, values are well formed (no timing is asserted), and
// bad options exit 2 leaving nothing behind.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
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

using test::CliResult;
using test::slurp;
using test::split_csv;

// A CSV file as a header and rows of name -> field (no quoted fields occur
// in bench output; a quote would fail the test).
struct Csv {
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
};

Csv read_csv(const fs::path& p) {
  Csv c;
  std::istringstream in(slurp(p));
  std::string line;
  EXPECT_TRUE(std::getline(in, line)) << p;
  c.header = split_csv(line);
  while (std::getline(in, line)) {
    EXPECT_EQ(line.find('"'), std::string::npos) << line;
    const auto f = split_csv(line);
    EXPECT_EQ(f.size(), c.header.size()) << p << ": " << line;
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < f.size() && i < c.header.size(); ++i) row[c.header[i]] = f[i];
    c.rows.push_back(std::move(row));
  }
  return c;
}

double number(const std::string& s) {
  size_t used = 0;
  const double v = std::stod(s, &used);
  EXPECT_EQ(used, s.size()) << s;
  return v;
}

class Bench : public test::CliTest {
 protected:
  Bench() : CliTest("hprt_bench_") {}
  void generate(const std::string& kind, int tris, const std::string& name) const {
    const CliResult r =
        run("generate " + kind + " --tris " + std::to_string(tris) + " -o " + path(name));
    ASSERT_EQ(r.code, 0) << r.err;
  }
  // The JSON report: machine and Embree as Embree reports them, parameters,
  // and the table whose columns are exactly the CSV's.
  nlohmann::json check_json(const std::string& file, const std::string& table, const Csv& csv) {
    const auto j = nlohmann::json::parse(slurp(dir_ / "out" / file));
    EXPECT_FALSE(j["machine"]["cpu_model"].get<std::string>().empty());
    EXPECT_GE(j["machine"]["logical_cores"].get<int>(), 1);
    EXPECT_EQ(j["machine"]["embree_version"].get<std::string>().substr(0, 2), "3.");
    EXPECT_FALSE(j["machine"]["embree_isa"].get<std::string>().empty());
    EXPECT_FALSE(j["machine"]["embree_tasking"].get<std::string>().empty());
    EXPECT_TRUE(j["params"].contains("repetitions"));
    EXPECT_TRUE(j["params"].contains("threads"));
    EXPECT_EQ(j["params"]["quick"], true);
    const auto& t = j["tables"][table];
    EXPECT_EQ(t["columns"].get<std::vector<std::string>>(), csv.header);
    EXPECT_EQ(t["rows"].size(), csv.rows.size());
    for (const auto& row : t["rows"])
      for (const auto& col : csv.header) EXPECT_TRUE(row.contains(col)) << col;
    return j;
  }
};

TEST_F(Bench, BuildQuickWritesEveryColumnAndEmbreeRows) {
  generate("sphere", 2000, "tiny.ply");
  const CliResult r =
      run("bench build " + path("tiny.ply") + " --quick --threads 2 --out " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| mesh"), std::string::npos) << r.out;  // the Markdown table
  EXPECT_NE(r.out.find("Embree 3."), std::string::npos);
  const Csv csv = read_csv(dir_ / "out" / "build_table.csv");
  const std::vector<std::string> columns = {"mesh",
                                            "triangles",
                                            "report_model",
                                            "builder",
                                            "threads",
                                            "reps",
                                            "build_ms",
                                            "min_ms",
                                            "max_ms",
                                            "mtris_per_s",
                                            "speedup",
                                            "sah_cost",
                                            "sah_vs_embree_bvh",
                                            "bytes_per_tri",
                                            "nodes",
                                            "depth"};
  EXPECT_EQ(csv.header, columns);
  std::multiset<std::string> builders;
  for (const auto& row : csv.rows) {
    builders.insert(row.at("builder"));
    EXPECT_EQ(row.at("mesh"), "tiny.ply");
    EXPECT_GE(number(row.at("triangles")), 2000.0);  // a sphere has at least --tris
    EXPECT_GE(number(row.at("build_ms")), 0.0);
    EXPECT_LE(number(row.at("min_ms")), number(row.at("max_ms")));
    EXPECT_TRUE(row.at("threads") == "1" || row.at("threads") == "2");
    EXPECT_EQ(row.at("reps"), "1");
    // Cold first builds (a child hprt trace each): a time, no tree figures.
    if (row.at("builder").rfind("cold-process-", 0) == 0) {
      EXPECT_GT(number(row.at("build_ms")), 0.0) << row.at("builder");
      EXPECT_EQ(row.at("sah_cost"), "");
      continue;
    }
    if (row.at("builder").rfind("embree-commit", 0) != 0) {
      EXPECT_GT(number(row.at("sah_cost")), 1.0) << row.at("builder");
      EXPECT_GT(number(row.at("sah_vs_embree_bvh")), 0.5);
    }
    if (row.at("builder").rfind("embree-buildbvh", 0) != 0) {
      EXPECT_GT(number(row.at("bytes_per_tri")), 0.0) << row.at("builder");
    }
  }
  for (const char* b : {"sweep", "presorted", "binned", "parallel", "morton", "embree-commit-low",
                        "embree-commit-medium", "embree-commit-high", "embree-buildbvh",
                        "cold-process-bvh", "cold-process-embree-medium"})
    EXPECT_EQ(builders.count(b), 2u) << b;  // 1 thread and 2 threads
  check_json("build.json", "table", csv);
}

TEST_F(Bench, TraceQuickHasBothBackendsAndEveryRayKind) {
  std::ofstream(path("scene.json")) << R"({
    "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "focal_length_mm": 20},
    "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [1, 1, 1]}],
    "meshes": [
      {"generate": {"kind": "plane", "tris": 2}, "transform": {"scale": 4},
       "material": {"diffuse": [0.6, 0.6, 0.6], "reflectivity": 0.3}},
      {"generate": {"kind": "sphere", "tris": 1000}, "transform": {"translate": [0, 1, 0]},
       "material": {"diffuse": [0.8, 0.2, 0.2], "reflectivity": 0.5}}
    ]})";
  generate("sphere", 500, "extra.ply");
  const CliResult r = run("bench trace " + path("scene.json") +
                          " --quick --threads 2 --rays 2000 --layout bvh4 --suite-tris 2000 "
                          "--meshes " +
                          path("extra.ply") + " --out " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(slurp(dir_ / "out" / "trace.json").find("watertight test, bvh4 layout"),
            std::string::npos);
  const Csv render = read_csv(dir_ / "out" / "trace_render.csv");
  // 2 focal lengths x 2 resolutions x 2 backends x 2 thread counts.
  EXPECT_EQ(render.rows.size(), 16u);
  std::set<std::string> focal, res, backends;
  for (const auto& row : render.rows) {
    focal.insert(row.at("focal_mm"));
    res.insert(row.at("resolution"));
    backends.insert(row.at("backend"));
    EXPECT_GT(number(row.at("rays")), 0.0);
    EXPECT_GT(number(row.at("mrays_per_s")), 0.0);
    if (row.at("backend") == "embree") {
      EXPECT_FALSE(row.at("bvh_over_embree_time").empty());
    }
  }
  EXPECT_EQ(focal, (std::set<std::string>{"6", "13"}));
  EXPECT_EQ(res.size(), 2u);
  EXPECT_EQ(backends, (std::set<std::string>{"bvh", "embree"}));
  check_json("trace.json", "render", render);

  const Csv rays = read_csv(dir_ / "out" / "trace_rays.csv");
  std::multiset<std::string> kinds;
  std::map<std::string, int> rows_per_input;
  size_t counts = 0;
  std::map<std::string, int> point_rows;  // "points-<kind> <query>"
  for (const auto& row : rays.rows) {
    kinds.insert(row.at("ray_kind"));
    ++rows_per_input[row.at("scene")];
    EXPECT_GT(number(row.at("bvh_mrays_per_s")), 0.0);
    EXPECT_GT(number(row.at("embree_mrays_per_s")), 0.0);
    EXPECT_GT(number(row.at("bvh_over_embree")), 0.0);
    EXPECT_GE(number(row.at("bvh_exact_per_mray")), 0.0);
    if (row.at("ray_kind").starts_with("points-")) {
      // Inside on every point, closest on a tenth of them.
      ++point_rows[row.at("ray_kind") + " " + row.at("query")];
      EXPECT_EQ(row.at("rays"), row.at("query") == "closest" ? "200" : "2000");
      continue;
    }
    EXPECT_EQ(row.at("rays"), "2000");
    if (row.at("query") == "count") {
      EXPECT_EQ(row.at("ray_kind"), "random");
      ++counts;
      continue;
    }
    EXPECT_EQ(row.at("query"), row.at("ray_kind") == "shadow" ? "occluded" : "intersect");
  }
  // The scene and the large-mesh suite (generated bumpy sphere, soup and
  // sliver sheet, and the mesh given): every kind, the crossing counts of
  // the random rays and the four point-query rows, at 1 and 2 threads.
  const std::map<std::string, int> expected_inputs{{"scene.json", 20},
                                                   {"bumpy-2000", 20},
                                                   {"soup-2000", 20},
                                                   {"sheet-3200", 20},
                                                   {"extra.ply", 20}};
  EXPECT_EQ(rows_per_input, expected_inputs);
  EXPECT_EQ(counts, 10u);
  const std::map<std::string, int> expected_points{{"points-random inside", 10},
                                                   {"points-random closest", 10},
                                                   {"points-near inside", 10},
                                                   {"points-near closest", 10}};
  EXPECT_EQ(point_rows, expected_points);
  for (const char* k : {"primary", "shadow", "reflection", "diffuse"})
    EXPECT_EQ(kinds.count(k), 10u) << k;
  EXPECT_EQ(kinds.count("random"), 20u);
  check_json("trace.json", "rays", rays);

  // One memory row per input: both structures' bytes per triangle.
  const Csv memory = read_csv(dir_ / "out" / "trace_memory.csv");
  ASSERT_EQ(memory.rows.size(), expected_inputs.size());
  for (const auto& row : memory.rows) {
    EXPECT_EQ(expected_inputs.count(row.at("scene")), 1u) << row.at("scene");
    EXPECT_GT(number(row.at("bvh_bytes_per_tri")), 8.0);  // at least the triangle indices
    EXPECT_GT(number(row.at("embree_bytes_per_tri")), 8.0);
    EXPECT_NEAR(number(row.at("bvh_over_embree_bytes")),
                number(row.at("bvh_bytes_per_tri")) / number(row.at("embree_bytes_per_tri")), 0.01);
  }
  check_json("trace.json", "memory", memory);
}

TEST_F(Bench, FrontierQuickRowsErrorsAndPareto) {
  generate("sphere", 1500, "closed.ply");
  const CliResult r =
      run("bench frontier " + path("closed.ply") +
          " --quick --threads 2 --hard-rays 100 --trace-rays 2000 --out " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Csv csv = read_csv(dir_ / "out" / "frontier_table.csv");
  std::map<std::string, std::map<std::string, std::string>> by_config;
  size_t pareto = 0, defaults = 0;
  for (const auto& row : csv.rows) {
    by_config[row.at("config")] = row;
    EXPECT_GT(number(row.at("mrays_per_s")), 0.0);
    EXPECT_EQ(row.at("hard_rays"), "800");  // 8 sets x 100 rays
    const double wrong = number(row.at("wrong_rays"));
    EXPECT_EQ(wrong, number(row.at("wrong_probe")) + number(row.at("wrong_grazing")) +
                         number(row.at("wrong_axis")) + number(row.at("wrong_offset")));
    pareto += row.at("pareto") == "yes";
    defaults += row.at("default") == "yes";
  }
  EXPECT_GE(pareto, 1u);
  EXPECT_EQ(defaults, 1u);
  ASSERT_TRUE(by_config.count("bvh/sweep/leaf4/watertight"));
  const auto& ref = by_config["bvh/sweep/leaf4/watertight"];
  EXPECT_EQ(ref.at("psnr_db"), "inf");  // the reference against itself
  EXPECT_EQ(number(ref.at("sah_vs_sweep")), 1.0);
  for (const char* c :
       {"embree/medium/robust-off", "embree/medium/robust-on",
        "bvh/parallel/bins32/leaf4/watertight", "bvh/parallel/bins32/leaf4/mt",
        "bvh/binned/bins4/leaf4/watertight", "bvh/binned/bins64/leaf4/watertight",
        "bvh/presorted/leaf4/watertight", "bvh/parallel/bins32/leaf1/watertight",
        "bvh/parallel/bins32/leaf8/watertight", "bvh/parallel/bins32/leaf4/watertight/bvh2",
        "bvh/parallel/bins32/leaf4/watertight/bvh4"})
    EXPECT_TRUE(by_config.count(c)) << c;
  // The layouts store the same tree: same answers, same SAH cost.
  for (const char* c :
       {"bvh/parallel/bins32/leaf4/watertight/bvh2", "bvh/parallel/bins32/leaf4/watertight/bvh4"}) {
    EXPECT_EQ(by_config[c].at("wrong_rays"), "0") << c;
    EXPECT_EQ(by_config[c].at("sah_cost"),
              by_config["bvh/parallel/bins32/leaf4/watertight"].at("sah_cost"))
        << c;
  }
  EXPECT_EQ(by_config["bvh/parallel/bins32/leaf4/watertight"].at("default"), "yes");
  EXPECT_TRUE(by_config["embree/medium/robust-on"].at("sah_cost").empty());
  check_json("frontier.json", "table", csv);
  // The plot comes with gnuplot; without it the report says why.
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_TRUE(fs::exists(dir_ / "out" / "frontier.png"));
  }
  for (const auto& e : fs::directory_iterator(dir_ / "out"))  // no temporaries left
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(Bench, BadOptionsExitTwo) {
  generate("sphere", 200, "tiny.ply");
  CliResult r = run("bench build " + path("tiny.ply") + " --quick --repeat 0 --out " + path("out"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--repeat"), std::string::npos) << r.err;
  r = run("bench build " + path("missing.ply") + " --quick");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.ply"), std::string::npos) << r.err;
  r = run("bench frontier " + path("missing.obj") + " --quick");
  EXPECT_EQ(r.code, 2);
  r = run("bench trace " + path("missing.json") + " --quick");
  EXPECT_EQ(r.code, 2);
  r = run("bench trace --quick --threads -1");
  EXPECT_EQ(r.code, 2);
  // Beyond the bounds: errors before anything is sized by them (a task
  // arena of 1e9 threads crashed oneTBB; 1e11 rays ran out of memory).
  r = run("bench trace --quick --threads 1000000000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
  r = run("bench trace --quick --no-suite --rays 100000000000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--rays: too many rays"), std::string::npos) << r.err;
  r = run("bench build --quick --repeat 1000000000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--repeat"), std::string::npos) << r.err;
  r = run("bench frontier --quick --hard-rays 100000000000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--hard-rays"), std::string::npos) << r.err;
  r = run("bench trace --quick --meshes " + path("missing.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.ply"), std::string::npos) << r.err;
  r = run("bench trace --quick --suite-tris 300000000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--suite-tris"), std::string::npos) << r.err;
  r = run("bench");  // a subcommand is required
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(dir_ / "out" / "build.json"));
}

}  // namespace
}  // namespace hprt
