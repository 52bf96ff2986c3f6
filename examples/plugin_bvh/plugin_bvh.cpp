// hprt's bvh backend behind the C plugin ABI (<hprt/plugin.h>), through the
// public C++ API: create() takes the backend options as key=value pairs
// separated by commas (builder=morton,layout=bvh4,...), build() shares the
// meshes hprt passes (the ABI keeps them valid until the next build, update
// or destroy) in an hprt::api::Scene, and intersect()/occluded() pass the
// caller's records straight through (hprt::api::Ray is hprt_ray). No
// threads option: hprt calls in from its own threads and the backend runs
// in the caller's arena.
#include <hprt/hprt.h>
#include <hprt/plugin.h>

#include <cstdio>
#include <exception>
#include <memory>
#include <new>
#include <span>
#include <string>

namespace api = hprt::api;

struct hprt_backend {
  api::Options options;
  api::Scene scene;
  std::unique_ptr<api::Backend> backend;
};

namespace {

void set_error(char* error, size_t size, const char* message) {
  if (error && size > 0) std::snprintf(error, size, "%s", message);
}

// Runs f; a C++ exception becomes the ABI's error message and code 1.
template <typename F>
int guarded(char* error, size_t size, F&& f) {
  try {
    f();
    return 0;
  } catch (const std::exception& e) {
    set_error(error, size, e.what());
  } catch (...) {
    set_error(error, size, "unknown C++ exception");
  }
  return 1;
}

api::Options parse_options(const std::string& text) {
  api::Options o;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw api::Error("option '" + item + "' is not key=value");
    if (item.substr(0, eq) == "threads")
      throw api::Error("threads: not an option of this plugin (hprt's --threads applies)");
    o[item.substr(0, eq)] = item.substr(eq + 1);
    start = end + 1;
  }
  return o;
}

hprt_backend* create(const char* options, int /*threads*/, char* error, size_t size) {
  auto b = std::make_unique<hprt_backend>();
  const int rc = guarded(error, size, [&] {
    b->options = parse_options(options ? options : "");
    b->backend = std::make_unique<api::Backend>("bvh", b->options);  // checks the options now
  });
  return rc == 0 ? b.release() : nullptr;
}

int build(hprt_backend* b, const hprt_mesh* meshes, uint32_t count, char* error, size_t size) {
  return guarded(error, size, [&] {
    b->scene = api::Scene();
    for (uint32_t m = 0; m < count; ++m)
      b->scene.add_mesh_shared({meshes[m].vertices, size_t(meshes[m].vertex_count) * 3},
                               {meshes[m].indices, size_t(meshes[m].triangle_count) * 3});
    b->backend->build(b->scene);
  });
}

int update(hprt_backend* b, const hprt_mesh* meshes, uint32_t count, char* error, size_t size) {
  return guarded(error, size, [&] {
    if (count != b->scene.mesh_count()) throw api::Error("update: the mesh count changed");
    for (uint32_t m = 0; m < count; ++m)
      b->scene.set_vertices(m, {meshes[m].vertices, size_t(meshes[m].vertex_count) * 3});
    b->backend->update(b->scene);
  });
}

void intersect(const hprt_backend* b, const hprt_ray* rays, hprt_hit* hits, size_t count) {
  b->backend->intersect({rays, count}, {hits, count});
}

void occluded(const hprt_backend* b, const hprt_ray* rays, uint8_t* out, size_t count) {
  b->backend->occluded({rays, count}, {out, count});
}

void destroy(hprt_backend* b) { delete b; }

constexpr hprt_plugin_v1 kTable = {
    HPRT_PLUGIN_ABI_VERSION, "hprt-bvh", create, build, update, intersect, occluded, destroy};

}  // namespace

extern "C" HPRT_PLUGIN_EXPORT const hprt_plugin_v1* hprt_plugin_entry(void) { return &kTable; }
