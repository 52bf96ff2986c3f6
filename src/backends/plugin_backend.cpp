// The plugin backend: dlopen, check the table, then batch calls split into
// blocks that oneTBB hands to the caller's arena (hprt calls the plugin from
// its own threads, as Embree's API is called). Every answer is checked
// (core/hit_check.h): a malformed hit becomes malformed_hit(), a miss that
// the ray diff counts as wrong; a malformed occlusion byte is kept as it is
// (nonzero reads as occluded) for the ray diff to count.
#include "backends/plugin_backend.h"

#include <dlfcn.h>
#include <hprt/plugin.h>
#include <sys/stat.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/hit_check.h"
#include "core/stopwatch.h"

namespace hprt {

// The ABI's records are hprt's own, so batches pass without copies.
static_assert(sizeof(hprt_ray) == sizeof(Ray) &&
              offsetof(hprt_ray, tnear) == offsetof(Ray, tnear) &&
              offsetof(hprt_ray, dir_x) == offsetof(Ray, dir) &&
              offsetof(hprt_ray, tfar) == offsetof(Ray, tfar));
static_assert(sizeof(hprt_hit) == sizeof(Hit) && offsetof(hprt_hit, u) == offsetof(Hit, u) &&
              offsetof(hprt_hit, geom_id) == offsetof(Hit, geom_id) &&
              offsetof(hprt_hit, prim_id) == offsetof(Hit, prim_id));
static_assert(sizeof(Vec3f) == 3 * sizeof(float) && sizeof(Vec3u) == 3 * sizeof(uint32_t));

namespace {

constexpr size_t kBlock = 256;  // rays per call into the plugin (a multiple of 16)
constexpr size_t kErrorSize = 1024;
constexpr uint8_t kUnwrittenByte = 0xfe;  // neither 0 nor 1: occlusion_well_formed fails

// The plugin's message, or a stand-in when it left none.
std::string plugin_message(const std::array<char, kErrorSize>& buf) {
  std::string m = one_line(std::string(buf.data(), std::find(buf.begin(), buf.end(), '\0')));
  return m.empty() ? "no message" : m;
}

const hprt_plugin_v1* load_table(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError(path, "plugin file not found");
  // dlopen() opens the file blocking: a FIFO would wait for ever.
  if (!S_ISREG(st.st_mode)) throw InputError(path, "not a regular file");
  // A bare file name means this directory, as for every other file argument.
  const std::string open_path = path.find('/') == std::string::npos ? "./" + path : path;
  // Never dlclose'd: a library that registered thread-local destructors or
  // atexit handlers must stay mapped until the process ends.
  void* lib = ::dlopen(open_path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    const char* e = ::dlerror();
    throw InputError(path, std::string("cannot load plugin: ") + (e ? e : "dlopen failed"));
  }
  using Entry = const hprt_plugin_v1* (*)();
  auto entry = reinterpret_cast<Entry>(::dlsym(lib, "hprt_plugin_entry"));
  if (!entry) throw InputError(path, "not an hprt plugin: no hprt_plugin_entry symbol");
  const hprt_plugin_v1* t = entry();
  if (!t) throw InputError(path, "hprt_plugin_entry() returned NULL");
  if (t->abi_version != HPRT_PLUGIN_ABI_VERSION)
    throw InputError(path, "plugin ABI version " + std::to_string(t->abi_version) +
                               ", this hprt loads version " +
                               std::to_string(HPRT_PLUGIN_ABI_VERSION));
  const std::pair<const char*, bool> required[] = {
      {"name", t->name != nullptr},         {"create", t->create != nullptr},
      {"build", t->build != nullptr},       {"intersect", t->intersect != nullptr},
      {"occluded", t->occluded != nullptr}, {"destroy", t->destroy != nullptr}};
  for (const auto& [field, present] : required)
    if (!present) throw InputError(path, std::string("plugin table has a NULL '") + field + "'");
  if (t->name[0] == '\0') throw InputError(path, "plugin table has an empty 'name'");
  return t;
}

class PluginIntersector final : public Intersector {
 public:
  PluginIntersector(const BackendSpec& spec, const BackendOptions& options)
      : path_(spec.plugin_path), table_(load_table(spec.plugin_path)), update_(options.update) {
    std::array<char, kErrorSize> err{};
    backend_ = table_->create(spec.plugin_options.c_str(), options.threads, err.data(), err.size());
    err.back() = '\0';
    if (!backend_) throw InputError(path_, "create failed: " + plugin_message(err));
    info_.name = "plugin/" + one_line(table_->name);  // printed in every table and line
  }
  ~PluginIntersector() override { table_->destroy(backend_); }
  PluginIntersector(const PluginIntersector&) = delete;
  PluginIntersector& operator=(const PluginIntersector&) = delete;

  void build(const Scene& scene) override {
    call_build(scene, table_->build, "build");
    info_.rebuilt = true;
  }

  // The plugin's update() only for the meshes of the last build with moved
  // vertices (plugin.h); anything else, or every frame under --update
  // rebuild, is built again.
  void update(const Scene& scene) override {
    if (!table_->update || update_ == UpdateStrategy::kRebuild || !same_meshes(scene))
      return build(scene);
    call_build(scene, table_->update, "update");
    info_.rebuilt = false;
  }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    if (hits.size() < rays.size())
      throw std::invalid_argument("intersect: fewer hit slots than rays");
    if (!scene_) throw std::logic_error("plugin: intersect() before build()");
    for_blocks(rays.size(), [&](size_t begin, size_t count) {
      // A record the plugin leaves unwritten stays malformed (t = NaN).
      std::fill_n(hits.begin() + begin, count, malformed_hit());
      table_->intersect(backend_, reinterpret_cast<const hprt_ray*>(rays.data() + begin),
                        reinterpret_cast<hprt_hit*>(hits.data() + begin), count);
      uint64_t bad = 0;
      for (size_t i = begin; i < begin + count; ++i) {
        if (!hit_well_formed(*scene_, rays[i], hits[i])) {
          hits[i] = malformed_hit();
          ++bad;
        } else if (!hits[i].hit()) {
          hits[i] = Hit{};
        }
      }
      if (bad) malformed_.fetch_add(bad, std::memory_order_relaxed);
    });
  }

  void occluded(const RayInput& rays, std::span<uint8_t> result) const override {
    if (result.size() < rays.size())
      throw std::invalid_argument("occluded: fewer result slots than rays");
    if (!scene_) throw std::logic_error("plugin: occluded() before build()");
    for_blocks(rays.size(), [&](size_t begin, size_t count) {
      alignas(64) Ray buf[kBlock];  // six-float rays as the ABI's records
      // A byte the plugin leaves unwritten stays malformed.
      std::fill_n(result.begin() + begin, count, kUnwrittenByte);
      table_->occluded(backend_, reinterpret_cast<const hprt_ray*>(rays.block(begin, count, buf)),
                       result.data() + begin, count);
      const auto bad = std::count_if(result.begin() + begin, result.begin() + begin + count,
                                     [](uint8_t o) { return !occlusion_well_formed(o); });
      if (bad) malformed_.fetch_add(uint64_t(bad), std::memory_order_relaxed);
    });
  }

  BuildInfo info() const override {
    BuildInfo i = info_;
    i.malformed_answers = malformed_.load(std::memory_order_relaxed);
    return i;
  }

 private:
  using BuildFn = int (*)(hprt_backend*, const hprt_mesh*, uint32_t, char*, size_t);

  template <typename F>
  static void for_blocks(size_t n, F&& f) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, (n + kBlock - 1) / kBlock, 1),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t b = r.begin(); b != r.end(); ++b)
                          f(b * kBlock, std::min(kBlock, n - b * kBlock));
                      });
  }

  void call_build(const Scene& scene, BuildFn fn, const char* what) {
    constexpr size_t kMax = std::numeric_limits<uint32_t>::max();
    if (scene.meshes.size() > kMax) throw InputError(path_, "too many meshes for the plugin ABI");
    std::vector<hprt_mesh> meshes;
    meshes.reserve(scene.meshes.size());
    for (const TriangleMesh& m : scene.meshes) {
      if (m.vertex_count() > kMax || m.triangle_count() > kMax)
        throw InputError(m.name, "more than 2^32-1 vertices or triangles for the plugin ABI");
      meshes.push_back({reinterpret_cast<const float*>(m.positions.data()),
                        reinterpret_cast<const uint32_t*>(m.triangles.data()),
                        uint32_t(m.vertex_count()), uint32_t(m.triangle_count())});
    }
    std::array<char, kErrorSize> err{};
    const auto start = Clock::now();
    const int rc = fn(backend_, meshes.data(), uint32_t(meshes.size()), err.data(), err.size());
    info_.build_ms = ms_since(start);
    err.back() = '\0';
    built_counts_.clear();
    if (rc != 0) {
      scene_ = nullptr;
      throw InputError(path_, std::string(what) + " failed: " + plugin_message(err));
    }
    scene_ = &scene;
    for (const TriangleMesh& m : scene.meshes)
      built_counts_.emplace_back(m.vertex_count(), m.triangle_count());
  }

  bool same_meshes(const Scene& scene) const {
    if (!scene_ || scene.meshes.size() != built_counts_.size()) return false;
    for (size_t i = 0; i < built_counts_.size(); ++i)
      if (built_counts_[i] !=
          std::pair(scene.meshes[i].vertex_count(), scene.meshes[i].triangle_count()))
        return false;
    return true;
  }

  std::string path_;
  const hprt_plugin_v1* table_;
  UpdateStrategy update_;
  hprt_backend* backend_ = nullptr;
  const Scene* scene_ =
      nullptr;  // answers are checked against it; outlives the build (as Embree's shared buffers)
  BuildInfo info_;
  std::vector<std::pair<size_t, size_t>>
      built_counts_;  // vertices, triangles per mesh at the last build
  mutable std::atomic<uint64_t> malformed_{0};
};

}  // namespace

std::unique_ptr<Intersector> make_plugin_intersector(const BackendSpec& spec,
                                                     const BackendOptions& options) {
  return std::make_unique<PluginIntersector>(spec, options);
}

}  // namespace hprt
