// The `hprt` Python module: numpy arrays in and out of
// hprt::raycasting::RaycastingScene (src/raycasting) and the public API
// (include/hprt/hprt.h). Only conversions live here: dtype and shape checks,
// rays and points read in place where their dtype and layout allow (meshes
// are copied, as Open3D copies them), results written into fresh arrays,
// the GIL released around every build and query, and errors turned into
// Python exceptions with the CLI's one-line message.
#include <hprt/hprt.h>
#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "raycasting/raycasting_scene.h"

namespace py = pybind11;
namespace rc = hprt::raycasting;
namespace api = hprt::api;

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using IdArray = py::array_t<uint32_t, py::array::c_style | py::array::forcecast>;

// A float array of shape (..., last), or (N, last) when `two_d`, float32
// C-contiguous (read in place when it already is; float64 and other real
// dtypes converted once).
FloatArray float_array(const py::handle& obj, const char* name, py::ssize_t last,
                       bool two_d = false) {
  py::array a = py::array::ensure(obj);
  if (!a) throw py::type_error(std::string(name) + ": expected an array-like of numbers");
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
    throw py::type_error(std::string(name) + ": expected a real dtype, got " +
                         std::string(py::str(a.dtype())));
  if (a.ndim() < 1 || a.shape(a.ndim() - 1) != last || (two_d && a.ndim() != 2))
    throw py::value_error(std::string(name) + ": expected shape (" + (two_d ? "N" : "...") + ", " +
                          std::to_string(last) + "), got " +
                          std::string(py::str(py::tuple(py::cast(
                              std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()))))));
  // The converting constructor, not ensure(): a failed conversion (numpy's
  // MemoryError) propagates instead of being cleared into a null array.
  return FloatArray(a);
}

// (M, 3) triangle indices of any integer dtype, each in [0, vertices).
IdArray index_array(const py::handle& obj, size_t vertices) {
  py::array a = py::array::ensure(obj);
  if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw py::type_error("triangle_indices: expected an integer array-like");
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error("triangle_indices: expected shape (M, 3)");
  // Range checks in 64 bits (uint64 for unsigned dtypes, else int64) so that
  // negative and > 2^32 values are caught, and named, before the cast.
  IdArray ids;
  if (a.dtype().kind() == 'u') {
    const py::array_t<uint64_t, py::array::c_style | py::array::forcecast> wide(a);
    const uint64_t* p = wide.data();
    for (py::ssize_t i = 0; i < wide.size(); ++i)
      if (p[i] >= vertices)
        throw py::value_error("triangle_indices: index " + std::to_string(p[i]) +
                              " out of range (" + std::to_string(vertices) + " vertices)");
    ids = IdArray(a.dtype().is(py::dtype::of<uint32_t>()) ? a : py::array(wide));
  } else {
    const py::array_t<int64_t, py::array::c_style | py::array::forcecast> wide(a);
    const int64_t* p = wide.data();
    for (py::ssize_t i = 0; i < wide.size(); ++i)
      if (p[i] < 0 || uint64_t(p[i]) >= vertices)
        throw py::value_error("triangle_indices: index " + std::to_string(p[i]) +
                              " out of range (" + std::to_string(vertices) + " vertices)");
    ids = IdArray(wide);
  }
  return ids;
}

// The leading dimensions of an (..., k) array.
std::vector<py::ssize_t> leading(const py::array& a) {
  return std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim() - 1);
}
std::vector<py::ssize_t> with_last(std::vector<py::ssize_t> shape, py::ssize_t k) {
  shape.push_back(k);
  return shape;
}

// api::Error as FileNotFoundError when `path` does not exist, else hprt.Error.
[[noreturn]] void rethrow_for_path(const api::Error& e, const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    PyErr_SetString(PyExc_FileNotFoundError, e.what());
    throw py::error_already_set();
  }
  throw;
}

api::Options options_of(const py::kwargs& kwargs) {
  api::Options o;
  for (const auto& [key, value] : kwargs)
    o[py::str(key)] = py::isinstance<py::bool_>(value)
                          ? std::string(value.cast<bool>() ? "on" : "off")
                          : std::string(py::str(value));
  return o;
}

// The memory every query's result arrays come from: one api::ResultMemory
// for the process (a call repeated after the last call's results were
// freed reuses their pages, whichever scene made them; what it keeps is
// bounded for the process, not per scene). Never destroyed: arrays freed at
// interpreter exit still give their blocks back.
const std::shared_ptr<api::ResultMemory>& process_result_memory() {
  static const auto* memory =
      new std::shared_ptr<api::ResultMemory>(std::make_shared<api::ResultMemory>());
  return *memory;
}

// A scene: it copies the arrays it is given, as Open3D's does, so the
// caller may reuse or change them (and a plugin may keep pointers into the
// scene's own, plugin.h).
struct PyScene {
  std::unique_ptr<rc::RaycastingScene> scene;
};

// A fresh, uninitialised C-contiguous array from process_result_memory();
// its block goes back there when numpy frees the array (the block's owner
// shares the ResultMemory, so a result may outlive its scene).
template <typename T>
py::array_t<T> result_array(const std::vector<py::ssize_t>& shape) {
  const std::shared_ptr<api::ResultMemory>& memory = process_result_memory();
  struct Block {
    std::shared_ptr<api::ResultMemory> memory;
    void* p;
  };
  const auto free_block = [](void* b) {
    const auto* block = static_cast<Block*>(b);
    block->memory->release(block->p);
    delete block;
  };
  size_t n = 1;
  for (const py::ssize_t d : shape) n *= size_t(d);
  auto* block = new Block{memory, nullptr};
  py::capsule owner;
  try {
    block->p = memory->acquire(n * sizeof(T));
    owner = py::capsule(block, free_block);
  } catch (...) {
    free_block(block);
    throw;
  }
  return py::array_t<T>(shape, static_cast<T*>(block->p), owner);
}

// A plugin's malformed answers since `before` (RaycastingScene::malformed_since)
// as a RuntimeWarning, the CLI's warning line. (Queries of other threads
// meanwhile count too.)
void warn_malformed(const PyScene& s, uint64_t before) {
  std::string w;
  {
    py::gil_scoped_release nogil;
    w = s.scene->malformed_since(before);
  }
  if (!w.empty() && PyErr_WarnEx(PyExc_RuntimeWarning, w.c_str(), 1) != 0)
    throw py::error_already_set();
}

py::dict cast_rays(PyScene& s, const py::handle& rays_in, int nthreads) {
  const FloatArray rays = float_array(rays_in, "rays", 6);
  const std::vector<py::ssize_t> shape = leading(rays);
  auto t = result_array<float>(shape), uvs = result_array<float>(with_last(shape, 2)),
       normals = result_array<float>(with_last(shape, 3));
  auto geom = result_array<uint32_t>(shape), prim = result_array<uint32_t>(shape);
  const rc::CastOutput out{t.mutable_data(), geom.mutable_data(), prim.mutable_data(),
                           uvs.mutable_data(), normals.mutable_data()};
  uint64_t malformed = 0;
  {
    py::gil_scoped_release nogil;  // info() may wait for another thread's build
    malformed = s.scene->info().malformed_answers;
    s.scene->cast_rays({rays.data(), size_t(rays.size())}, out, nthreads);
  }
  warn_malformed(s, malformed);
  py::dict d;
  d["t_hit"] = t;
  d["geometry_ids"] = geom;
  d["primitive_ids"] = prim;
  d["primitive_uvs"] = uvs;
  d["primitive_normals"] = normals;
  return d;
}

py::array test_occlusions(PyScene& s, const py::handle& rays_in, float tnear, float tfar,
                          int nthreads) {
  const FloatArray rays = float_array(rays_in, "rays", 6);
  auto occluded = result_array<bool>(leading(rays));
  static_assert(sizeof(bool) == 1);
  uint64_t malformed = 0;
  {
    py::gil_scoped_release nogil;
    malformed = s.scene->info().malformed_answers;
    s.scene->test_occlusions({rays.data(), size_t(rays.size())}, tnear, tfar,
                             reinterpret_cast<uint8_t*>(occluded.mutable_data()), nthreads);
  }
  warn_malformed(s, malformed);
  return occluded;
}

py::array count_intersections(PyScene& s, const py::handle& rays_in, int nthreads) {
  const FloatArray rays = float_array(rays_in, "rays", 6);
  auto counts = result_array<int32_t>(leading(rays));
  {
    py::gil_scoped_release nogil;
    s.scene->count_intersections({rays.data(), size_t(rays.size())}, counts.mutable_data(),
                                 nthreads);
  }
  return counts;
}

py::dict compute_closest_points(PyScene& s, const py::handle& points_in, int nthreads) {
  const FloatArray points = float_array(points_in, "query_points", 3);
  const std::vector<py::ssize_t> shape = leading(points);
  auto q = result_array<float>(with_last(shape, 3)), uvs = result_array<float>(with_last(shape, 2)),
       normals = result_array<float>(with_last(shape, 3));
  auto geom = result_array<uint32_t>(shape), prim = result_array<uint32_t>(shape);
  const rc::ClosestOutput out{q.mutable_data(), geom.mutable_data(), prim.mutable_data(),
                              uvs.mutable_data(), normals.mutable_data()};
  {
    py::gil_scoped_release nogil;
    s.scene->compute_closest_points({points.data(), size_t(points.size())}, out, nthreads);
  }
  py::dict d;
  d["points"] = q;
  d["geometry_ids"] = geom;
  d["primitive_ids"] = prim;
  d["primitive_uvs"] = uvs;
  d["primitive_normals"] = normals;
  return d;
}

// compute_distance, compute_signed_distance, compute_occupancy: one float32
// per point, of the points' leading shape.
template <typename Query>
py::array point_floats(const py::handle& points_in, Query&& query) {
  const FloatArray points = float_array(points_in, "query_points", 3);
  auto result = result_array<float>(leading(points));
  {
    py::gil_scoped_release nogil;
    query(std::span<const float>(points.data(), size_t(points.size())), result.mutable_data());
  }
  return result;
}

template <typename T>
py::array_t<T> to_array(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* kept = new std::vector<T>(std::move(v));
  py::capsule owner(kept, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, kept->data(), owner);
}

py::dict list_intersections(PyScene& s, const py::handle& rays_in, int nthreads) {
  const FloatArray rays = float_array(rays_in, "rays", 6);
  rc::IntersectionLists l;
  {
    py::gil_scoped_release nogil;
    l = s.scene->list_intersections({rays.data(), size_t(rays.size())}, nthreads);
  }
  const auto n = py::ssize_t(l.t_hit.size()), splits = py::ssize_t(l.ray_splits.size());
  py::dict d;
  d["ray_splits"] = to_array(std::move(l.ray_splits), {splits});
  d["ray_ids"] = to_array(std::move(l.ray_ids), {n});
  d["geometry_ids"] = to_array(std::move(l.geometry_ids), {n});
  d["primitive_ids"] = to_array(std::move(l.primitive_ids), {n});
  d["primitive_uvs"] = to_array(std::move(l.primitive_uvs), {n, 2});
  d["t_hit"] = to_array(std::move(l.t_hit), {n});
  return d;
}

// A file path given as str, bytes or os.PathLike (pathlib.Path), as
// Python's own file functions take it; `what` names the call for a TypeError.
std::string path_of(const py::handle& obj, const char* what) {
  if (!py::isinstance<py::str>(obj) && !py::isinstance<py::bytes>(obj) &&
      !py::hasattr(obj, "__fspath__"))
    throw py::type_error(std::string(what) + ": expected a path (str, bytes or os.PathLike)");
  const py::module_ os = py::module_::import("os");
  return py::str(os.attr("fsdecode")(os.attr("fspath")(obj)));
}

uint32_t add_triangles(PyScene& s, const py::object& first, const py::object& second) {
  if (second.is_none()) {
    if (!py::isinstance<py::str>(first) && !py::isinstance<py::bytes>(first) &&
        !py::hasattr(first, "__fspath__"))
      throw py::type_error(
          "add_triangles: expected (vertex_positions, triangle_indices) or a path");
    const std::string path = path_of(first, "add_triangles");
    try {
      py::gil_scoped_release nogil;
      return s.scene->add_triangles(path);
    } catch (const api::Error& e) {
      rethrow_for_path(e, path);
    }
  }
  const FloatArray v = float_array(first, "vertex_positions", 3, /*two_d=*/true);
  const IdArray i = index_array(second, size_t(v.shape(0)));
  py::gil_scoped_release nogil;
  return s.scene->add_triangles({v.data(), size_t(v.size())}, {i.data(), size_t(i.size())},
                                /*shared=*/false);
}

void update_triangles(PyScene& s, uint32_t id, const py::handle& vertices) {
  const FloatArray v = float_array(vertices, "vertex_positions", 3, /*two_d=*/true);
  py::gil_scoped_release nogil;
  s.scene->update_triangles(id, {v.data(), size_t(v.size())}, /*shared=*/false);
}

py::dict info(const PyScene& s) {
  const rc::SceneInfo i = s.scene->info();
  py::dict d;
  d["backend"] = i.backend;
  d["build_ms"] = i.build_ms;
  d["memory_bytes"] = i.memory_bytes;
  d["normals_bytes"] = i.normals_bytes;
  d["result_cache_bytes"] = process_result_memory()->cached_bytes();
  d["geometries"] = i.meshes;
  d["triangles"] = i.triangles;
  d["malformed_answers"] = i.malformed_answers;
  return d;
}

py::array to_rays_array(const std::vector<float>& rays, int width, int height) {
  py::array_t<float> out({py::ssize_t(height), py::ssize_t(width), py::ssize_t(6)});
  std::copy(rays.begin(), rays.end(), out.mutable_data());
  return out;
}

std::vector<double> doubles(const py::handle& obj, const char* name, size_t n) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || size_t(a.size()) != n)
    throw py::value_error(std::string(name) + ": expected " + std::to_string(n) + " numbers");
  return std::vector<double>(a.data(), a.data() + n);
}

py::dict validate_rays(PyScene& s, const py::handle& rays_in, const std::string& reference) {
  const FloatArray rays = float_array(rays_in, "rays", 6);
  api::DiffReport r;
  {
    py::gil_scoped_release nogil;
    r = s.scene->validate_rays({rays.data(), size_t(rays.size())}, reference);
  }
  py::array_t<uint8_t> verdicts(leading(rays));
  std::copy(r.verdicts.begin(), r.verdicts.end(),
            reinterpret_cast<api::Verdict*>(verdicts.mutable_data()));
  py::dict d;
  d["verdicts"] = verdicts;
  for (const auto& [k, v] : {std::pair<const char*, size_t>{"rays", r.rays},
                             {"agree", r.agree},
                             {"ties", r.ties},
                             {"mismatches", r.mismatches},
                             {"backend_right", r.backend_right},
                             {"reference_right", r.reference_right},
                             {"both_right", r.both_right},
                             {"both_wrong", r.both_wrong},
                             {"backend_malformed", r.backend_malformed},
                             {"reference_malformed", r.reference_malformed},
                             {"backend_wrong", r.backend_wrong()}})
    d[k] = v;
  d["summary"] = r.summary;
  return d;
}

}  // namespace

PYBIND11_MODULE(hprt, m) {
  m.doc() =
      "hprt: ray casting against triangle meshes with hprt's BVH, Embree or a plugin; "
      "Open3D's RaycastingScene API, numpy in and out.";
  m.attr("__version__") = api::version();
  py::register_exception<api::Error>(m, "Error", PyExc_RuntimeError);
  m.attr("INVALID_ID") = api::kInvalidId;

  py::class_<PyScene> cls(m, "RaycastingScene");
  cls.attr("INVALID_ID") = api::kInvalidId;
  cls.def(py::init([](int nthreads, const std::string& backend, const py::kwargs& kwargs) {
            return PyScene{
                std::make_unique<rc::RaycastingScene>(nthreads, backend, options_of(kwargs))};
          }),
          py::arg("nthreads") = 0, py::arg("backend") = "bvh",
          "backend: bvh, embree or plugin:PATH.so[:OPTIONS]; keyword options as the command "
          "line's (builder='morton', layout='bvh4', leaf_size=2, quality='high', robust=True, "
          "update='refit' (auto, rebuild, refit or adaptive; default auto), ...)")
      .def("add_triangles", &add_triangles, py::arg("vertex_positions"),
           py::arg("triangle_indices") = py::none(),
           "(N,3) vertices and (M,3) triangle indices (copied, as Open3D copies them: the "
           "caller may change or reuse its arrays), or a mesh file path (str, bytes or "
           "os.PathLike); returns the geometry id")
      .def("update_triangles", &update_triangles, py::arg("geometry_id"),
           py::arg("vertex_positions"),
           "moved vertices of a geometry (same count), copied; the next query refits or "
           "rebuilds per the backend's update option. Adding or moving triangles waits for "
           "the queries under way in other threads, and later queries wait for it")
      .def("cast_rays", &cast_rays, py::arg("rays"), py::arg("nthreads") = 0,
           "closest hits of (..., 6) rays [ox, oy, oz, dx, dy, dz]: a dict of t_hit (inf on a "
           "miss; NaN, with a RuntimeWarning, for a plugin's malformed answer), geometry_ids and "
           "primitive_ids (INVALID_ID on a miss), primitive_uvs (..., 2) "
           "and primitive_normals (..., 3): the hit triangle's unit normal (v1 - v0) x (v2 - v0), "
           "the same bits on every backend, 0 on a miss")
      .def("test_occlusions", &test_occlusions, py::arg("rays"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::arg("nthreads") = 0,
           "whether anything is hit with t in (tnear, tfar] along each ray (a bool array of "
           "the leading shape); 0 <= tnear <= tfar, else ValueError")
      .def("count_intersections", &count_intersections, py::arg("rays"), py::arg("nthreads") = 0,
           "surface crossings along each of (..., 6) rays, an int32 array of the leading shape; "
           "the bvh backend counts a ray exactly through a shared edge or vertex once (a fill "
           "rule), so the parity tells inside from outside for closed meshes")
      .def("list_intersections", &list_intersections, py::arg("rays"), py::arg("nthreads") = 0,
           "every crossing along each ray, nearest first: a dict of ray_splits (uint32, rays + 1: "
           "ray i's crossings are [ray_splits[i], ray_splits[i+1])), ray_ids, geometry_ids, "
           "primitive_ids (uint32), primitive_uvs (float32, (k, 2)) and t_hit (float32)")
      .def("compute_closest_points", &compute_closest_points, py::arg("query_points"),
           py::arg("nthreads") = 0,
           "the closest surface point of each of (..., 3) points: a dict of points (float32, "
           "(..., 3)), geometry_ids, primitive_ids (uint32), primitive_uvs (float32, (..., 2)) "
           "and primitive_normals (float32, (..., 3)); among triangles at exactly the same "
           "distance the smallest ids win")
      .def(
          "compute_distance",
          [](PyScene& s, const py::handle& points, int nthreads) {
            return point_floats(points, [&](std::span<const float> p, float* out) {
              s.scene->compute_distance(p, out, nthreads);
            });
          },
          py::arg("query_points"), py::arg("nthreads") = 0,
          "distance from each of (..., 3) points to the closest surface point (float32)")
      .def(
          "compute_signed_distance",
          [](PyScene& s, const py::handle& points, int nthreads, int nsamples) {
            return point_floats(points, [&](std::span<const float> p, float* out) {
              s.scene->compute_signed_distance(p, out, nthreads, nsamples);
            });
          },
          py::arg("query_points"), py::arg("nthreads") = 0, py::arg("nsamples") = 1,
          "distance to the surface, negative inside closed meshes and 0 exactly on the "
          "surface (float32); the bvh backend decides inside exactly, so nsamples (Open3D's "
          "vote count, odd and >= 1) changes nothing")
      .def(
          "compute_occupancy",
          [](PyScene& s, const py::handle& points, int nthreads, int nsamples) {
            return point_floats(points, [&](std::span<const float> p, float* out) {
              s.scene->compute_occupancy(p, out, nthreads, nsamples);
            });
          },
          py::arg("query_points"), py::arg("nthreads") = 0, py::arg("nsamples") = 1,
          "1.0 for points inside a closed mesh or exactly on its surface, else 0.0 (float32); "
          "exact on the bvh backend, nsamples as in compute_signed_distance")
      .def("info", &info,
           "backend configuration, build time, memory (memory_bytes: the backend's structure; "
           "normals_bytes: the triangle normals compute_closest_points keeps, 12 bytes per "
           "triangle once made; result_cache_bytes: the capacity of freed result arrays of 2 "
           "MiB or more kept for the next query's results, shared by every scene of the process, "
           "at most 256 MiB), geometry "
           "counts")
      .def_static(
          "create_rays_pinhole",
          [](double fov_deg, const py::handle& center, const py::handle& eye, const py::handle& up,
             int width_px, int height_px) {
            const auto c = doubles(center, "center", 3), e = doubles(eye, "eye", 3),
                       u = doubles(up, "up", 3);
            return to_rays_array(
                rc::create_rays_pinhole(fov_deg, c.data(), e.data(), u.data(), width_px, height_px),
                width_px, height_px);
          },
          py::arg("fov_deg"), py::arg("center"), py::arg("eye"), py::arg("up"), py::arg("width_px"),
          py::arg("height_px"))
      .def_static(
          "create_rays_pinhole",
          [](const py::handle& intrinsic, const py::handle& extrinsic, int width_px,
             int height_px) {
            const auto k = doubles(intrinsic, "intrinsic_matrix", 9),
                       e = doubles(extrinsic, "extrinsic_matrix", 16);
            return to_rays_array(rc::create_rays_pinhole(k.data(), e.data(), width_px, height_px),
                                 width_px, height_px);
          },
          py::arg("intrinsic_matrix"), py::arg("extrinsic_matrix"), py::arg("width_px"),
          py::arg("height_px"));

  m.def("validate_rays", &validate_rays, py::arg("scene"), py::arg("rays"),
        py::arg("reference") = "embree",
        "the scene's backend against `reference` on the rays, settled by the exact arbiter: "
        "per-ray verdicts and the counts and summary `hprt validate rays` prints");
  m.def(
      "render",
      [](const py::object& path, int width, int height, const std::string& backend,
         const py::kwargs& kwargs) {
        const std::string scene_path = path_of(path, "render");
        const api::Options options = options_of(kwargs);  // Python objects: with the GIL
        api::Image img;
        try {
          py::gil_scoped_release nogil;
          const api::Scene scene = api::Scene::from_file(scene_path);
          api::Backend b(backend, options);
          b.build(scene);
          img = api::render(scene, b, width, height);
        } catch (const api::Error& e) {
          rethrow_for_path(e, scene_path);
        }
        py::array_t<float> out({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)});
        std::copy(img.rgb.begin(), img.rgb.end(), out.mutable_data());
        return out;
      },
      py::arg("scene_path"), py::arg("width") = 0, py::arg("height") = 0,
      py::arg("backend") = "bvh", "a Whitted render: (H, W, 3) float32 linear RGB");
  m.def(
      "load_mesh",
      [](const py::object& path_like) {
        const std::string path = path_of(path_like, "load_mesh");
        api::MeshArrays mesh;
        try {
          py::gil_scoped_release nogil;
          mesh = api::load_mesh(path);
        } catch (const api::Error& e) {
          rethrow_for_path(e, path);
        }
        FloatArray v({py::ssize_t(mesh.vertices.size() / 3), py::ssize_t(3)});
        IdArray t({py::ssize_t(mesh.indices.size() / 3), py::ssize_t(3)});
        std::copy(mesh.vertices.begin(), mesh.vertices.end(), v.mutable_data());
        std::copy(mesh.indices.begin(), mesh.indices.end(), t.mutable_data());
        return py::make_tuple(v, t);
      },
      py::arg("path"), "(vertices (N,3) float32, triangles (M,3) uint32) of a mesh file");

  // pybind11's TypeError for arguments no overload takes spans several
  // lines and prints the arguments' reprs (a whole ray array): every
  // function and method is wrapped to raise it on one line instead, with
  // the argument types. (A catch-all overload cannot do it: pybind11 tries
  // overloads first without conversions, where it would win over an int
  // given for a float.)
  py::dict scope;
  scope["hprt"] = m;
  // clang-format off
  py::exec(R"py(
import functools

def one_line_type_errors(owner, name, qualname, skip):
    raw = owner.__dict__[name] if isinstance(owner, type) else getattr(owner, name)
    static = isinstance(raw, staticmethod)
    fn = raw.__func__ if static else raw

    @functools.wraps(fn)
    def call(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except TypeError as e:
            text = str(e)
            if "incompatible function arguments" not in text and \
                    "incompatible constructor arguments" not in text:
                raise
            types = [type(a).__name__ for a in args[skip:]]
            types += [k + "=" + type(v).__name__ for k, v in kwargs.items()]
            raise TypeError(qualname + "(): no signature takes (" + ", ".join(types) +
                            "); see help(hprt." + qualname + ")") from None

    setattr(owner, name, staticmethod(call) if static else call)

scene = hprt.RaycastingScene
one_line_type_errors(scene, "__init__", "RaycastingScene", 1)
for name in ("add_triangles", "update_triangles", "cast_rays", "test_occlusions",
             "count_intersections", "list_intersections", "compute_closest_points",
             "compute_distance", "compute_signed_distance", "compute_occupancy", "info"):
    one_line_type_errors(scene, name, "RaycastingScene." + name, 1)
one_line_type_errors(scene, "create_rays_pinhole", "RaycastingScene.create_rays_pinhole", 0)
for name in ("validate_rays", "render", "load_mesh"):
    one_line_type_errors(hprt, name, name, 0)
)py", scope);
  // clang-format on
}
