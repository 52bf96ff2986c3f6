// What the public Scene and Backend hold (include/hprt/hprt.h).
#pragma once

#include <hprt/hprt.h>
#include <tbb/task_arena.h>

#include <memory>
#include <optional>

#include "backends/intersector.h"
#include "core/scene.h"

namespace hprt::api {

struct Scene::Impl {
  hprt::Scene scene;
};

struct Backend::Impl {
  BackendOptions options;
  std::unique_ptr<Intersector> intersector;
  // Set when the options name a thread count; else work runs in the
  // caller's arena.
  std::unique_ptr<tbb::task_arena> arena;
  // The scene of the last build() or update(): intersect into columns reads
  // its triangles for the normals (Intersector::intersect_columns: Embree,
  // plugins, and the bvh backend's table with isect=mt).
  const hprt::Scene* scene = nullptr;

  template <typename F>
  decltype(auto) run(F&& f) const {
    if (arena) return arena->execute(std::forward<F>(f));
    return std::forward<F>(f)();
  }
  const Intersector& built() const;
};

}  // namespace hprt::api
