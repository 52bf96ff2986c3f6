// load_mesh throughput: a generated ~1M-triangle wavy grid written once to a
// temp dir as binary PLY, ASCII PLY and OBJ, then loaded repeatedly. Set
// HPRT_MESH_FILES=a.ply:b.obj.gz to also time real files (one benchmark each).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/triangle_mesh.h"
#include "io/files/atomic_file.h"
#include "io/mesh/mesh_reader.h"
#include "io/mesh/ply_writer.h"

namespace fs = std::filesystem;

namespace {

// 708 x 708 vertices -> 2 * 707 * 707 = 999,698 triangles.
constexpr int kGrid = 708;

hprt::TriangleMesh wavy_grid() {
  hprt::TriangleMesh m;
  m.positions.reserve(size_t(kGrid) * kGrid);
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x) {
      const float u = float(x) / (kGrid - 1), v = float(y) / (kGrid - 1);
      m.positions.push_back(hprt::Vec3f(u, 0.05f * std::sin(20 * u) * std::cos(17 * v), v));
    }
  for (int y = 0; y + 1 < kGrid; ++y)
    for (int x = 0; x + 1 < kGrid; ++x) {
      const uint32_t i = uint32_t(y * kGrid + x);
      m.triangles.push_back(hprt::Vec3u{{i, i + 1, i + kGrid + 1}});
      m.triangles.push_back(hprt::Vec3u{{i, i + kGrid + 1, i + kGrid}});
    }
  return m;
}

void write_obj(const hprt::TriangleMesh& m, const std::string& path) {
  std::string out;
  out.reserve(m.positions.size() * 40 + m.triangles.size() * 24);
  char b[32];
  for (const hprt::Vec3f& p : m.positions) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      out.append(b, std::to_chars(b, b + sizeof b, p[k]).ptr);
    }
    out += '\n';
  }
  for (const hprt::Vec3u& t : m.triangles) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      out.append(b, std::to_chars(b, b + sizeof b, t[k] + 1).ptr);
    }
    out += '\n';
  }
  hprt::write_file_atomic(path, out.data(), out.size());
}

// Writes the three files on first use; removes them at exit.
struct GeneratedFiles {
  fs::path dir;
  std::string binary_ply, ascii_ply, obj;
  GeneratedFiles() {
    dir = fs::temp_directory_path() / ("hprt_micro_mesh_load_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const hprt::TriangleMesh m = wavy_grid();
    binary_ply = (dir / "grid_binary.ply").string();
    ascii_ply = (dir / "grid_ascii.ply").string();
    obj = (dir / "grid.obj").string();
    hprt::write_ply(m, binary_ply, hprt::PlyFormat::kBinaryLittleEndian);
    hprt::write_ply(m, ascii_ply, hprt::PlyFormat::kAscii);
    write_obj(m, obj);
  }
  ~GeneratedFiles() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

const GeneratedFiles& files() {
  static const GeneratedFiles f;
  return f;
}

void time_load(benchmark::State& state, const std::string& path) {
  size_t tris = 0;
  for (auto _ : state) {
    hprt::TriangleMesh m = hprt::load_mesh(path);
    tris = m.triangle_count();
    benchmark::DoNotOptimize(m.positions.data());
  }
  state.counters["triangles"] = double(tris);
  state.counters["bytes"] = double(fs::file_size(path));
  state.counters["Mtris/s"] =
      benchmark::Counter(double(tris) * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_LoadBinaryPly(benchmark::State& s) { time_load(s, files().binary_ply); }
void BM_LoadAsciiPly(benchmark::State& s) { time_load(s, files().ascii_ply); }
void BM_LoadObj(benchmark::State& s) { time_load(s, files().obj); }

BENCHMARK(BM_LoadBinaryPly)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LoadAsciiPly)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LoadObj)->Unit(benchmark::kMillisecond)->UseRealTime();

// One benchmark per path in $HPRT_MESH_FILES (colon separated).
const int kRegistered = [] {
  const char* env = std::getenv("HPRT_MESH_FILES");
  if (!env) return 0;
  int n = 0;
  std::string list = env;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t end = std::min(list.find(':', start), list.size());
    const std::string path = list.substr(start, end - start);
    if (!path.empty()) {
      benchmark::RegisterBenchmark(("BM_LoadFile/" + fs::path(path).filename().string()).c_str(),
                                   [path](benchmark::State& s) { time_load(s, path); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
      ++n;
    }
    start = end + 1;
  }
  return n;
}();

}  // namespace
