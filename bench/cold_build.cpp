#include "bench/cold_build.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "core/ray.h"
#include "io/mesh/ply_writer.h"
#include "io/rays/ray_file.h"

extern char** environ;

namespace hprt::bench {

namespace fs = std::filesystem;

ColdBuilds::ColdBuilds(const BenchInput& in) {
  dir_ = fs::temp_directory_path() / ("hprt-cold-" + std::to_string(::getpid()));
  fs::create_directories(dir_);
  std::error_code ec;
  if (fs::is_regular_file(in.source, ec)) {
    scene_ = fs::absolute(in.source);
  } else {
    if (in.scene.meshes.size() != 1)
      throw std::runtime_error("cold build: " + in.label + " is neither a file nor one mesh");
    scene_ = dir_ / "mesh.ply";
    write_ply(in.scene.meshes[0], scene_.string());
  }
  // One ray from outside the scene through its centre: the child builds,
  // traces it and exits.
  const AABB box = in.scene.bounds();
  Ray r;
  r.org = box.max + (box.max - box.min);
  r.dir = box.center() - r.org;
  rays_ = dir_ / "one.rays";
  write_rays(rays_.string(), std::span<const Ray>(&r, 1));
}

ColdBuilds::~ColdBuilds() {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

double ColdBuilds::build_ms(const std::string& backend, int threads) const {
  const fs::path json = dir_ / "trace.json", hits = dir_ / "one.hits";
  const std::string exe = fs::read_symlink("/proc/self/exe").string();
  std::vector<std::string> args = {
      exe,     "trace",     scene_.string(),         "--rays", rays_.string(), "--backend",
      backend, "--threads", std::to_string(threads), "--json", "-o",           hits.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, json.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw std::runtime_error("cold build: cannot start " + exe);
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("cold build: hprt trace --backend " + backend + " on " +
                             scene_.string() + " failed");
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("build_ms") || !j["build_ms"].is_number())
    throw std::runtime_error("cold build: no build_ms in hprt trace's output");
  return j["build_ms"].get<double>();
}

}  // namespace hprt::bench
