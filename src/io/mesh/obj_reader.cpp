// OBJ loading: validate_obj_text() first, then tinyobjloader's
// LoadObjWithCallback() streams v/vn/f/usemtl into our mesh, so faces keep
// file order and any vertex count (its shape API caps faces at 255 vertices).
#include "io/mesh/obj_reader.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <filesystem>
#include <istream>
#include <map>
#include <streambuf>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.h"
#include "io/files/file_bytes.h"
#include "io/mesh/obj_validate.h"

namespace hprt {
namespace {

// Read-only streambuf over memory, so tinyobjloader parses our buffer without a copy.
class MemoryBuf : public std::streambuf {
 public:
  explicit MemoryBuf(std::string_view s) {
    char* p = const_cast<char*>(s.data());
    setg(p, p, p + s.size());
  }
};

// An .mtl larger than this is not a material library.
constexpr size_t kMaxMtlBytes = size_t{64} << 20;

// `mtllib NAME` read as every other input file is (read_file_bytes: regular
// files only, size-capped), not through tinyobjloader's own ifstream, which
// would block on a FIFO and read /dev/zero until memory ran out. A missing
// library is a warning (the default material); one that cannot be read is an
// InputError naming it.
class MtlReader : public tinyobj::MaterialReader {
 public:
  explicit MtlReader(std::string dir) : dir_(std::move(dir)) {}
  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* names, std::string* warn, std::string* err) override {
    const std::string path = dir_ + name;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      if (warn) *warn += "material library " + path + " not found\n";
      return false;
    }
    const std::string text = read_file_bytes(path, kMaxMtlBytes);
    MemoryBuf buf(text);
    std::istream in(&buf);
    tinyobj::LoadMtl(names, materials, &in, warn, err);
    return true;
  }

 private:
  std::string dir_;
};

struct ObjBuild {
  TriangleMesh mesh;
  std::vector<Vec3f> vn;
  std::vector<std::pair<uint32_t, uint32_t>> vertex_normal;  // (position, vn) per face vertex
  bool every_vertex_has_normal = true;
  std::vector<tinyobj::material_t> materials;
  std::vector<uint64_t> material_triangles;  // per material id
  std::vector<uint64_t> material_first_use;  // order of first use
  uint64_t uses = 0;
  int material = -1;
  bool bad_index = false;  // validate_obj_text() makes this unreachable
};

// Resolves a raw OBJ index (1-based, or negative = relative) against `count`.
int64_t resolve(int raw, size_t count) {
  return raw > 0 ? int64_t(raw) - 1 : int64_t(count) + int64_t(raw);
}

void on_vertex(void* u, tinyobj::real_t x, tinyobj::real_t y, tinyobj::real_t z, tinyobj::real_t) {
  static_cast<ObjBuild*>(u)->mesh.positions.push_back(Vec3f(float(x), float(y), float(z)));
}

void on_normal(void* u, tinyobj::real_t x, tinyobj::real_t y, tinyobj::real_t z) {
  static_cast<ObjBuild*>(u)->vn.push_back(Vec3f(float(x), float(y), float(z)));
}

void on_face(void* u, tinyobj::index_t* idx, int n) {
  ObjBuild& b = *static_cast<ObjBuild*>(u);
  const size_t nv = b.mesh.positions.size();
  uint32_t first = 0, prev = 0;
  for (int k = 0; k < n; ++k) {
    const int64_t v = resolve(idx[k].vertex_index, nv);
    if (idx[k].vertex_index == 0 || v < 0) {
      b.bad_index = true;
      return;
    }
    const uint32_t vi = static_cast<uint32_t>(v);
    if (idx[k].normal_index == 0) {
      b.every_vertex_has_normal = false;
    } else if (b.every_vertex_has_normal) {
      const int64_t ni = resolve(idx[k].normal_index, b.vn.size());
      if (ni < 0)
        b.bad_index = true;
      else
        b.vertex_normal.push_back({vi, static_cast<uint32_t>(ni)});
    }
    if (k == 0)
      first = vi;
    else if (k >= 2)
      b.mesh.triangles.push_back(Vec3u{{first, prev, vi}});
    prev = vi;
  }
  if (b.material >= 0 && n >= 3) {
    const size_t m = static_cast<size_t>(b.material);
    if (m >= b.material_triangles.size()) {
      b.material_triangles.resize(m + 1, 0);
      b.material_first_use.resize(m + 1, UINT64_MAX);
    }
    if (b.material_first_use[m] == UINT64_MAX) b.material_first_use[m] = b.uses++;
    b.material_triangles[m] += static_cast<uint64_t>(n - 2);
  }
}

void on_usemtl(void* u, const char*, int material_id) {
  static_cast<ObjBuild*>(u)->material = material_id;
}

void on_mtllib(void* u, const tinyobj::material_t* m, int n) {
  static_cast<ObjBuild*>(u)->materials.assign(m, m + n);
}

Material chosen_material(const ObjBuild& b) {
  int best = -1;
  for (size_t m = 0; m < b.material_triangles.size() && m < b.materials.size(); ++m) {
    if (b.material_triangles[m] == 0) continue;
    if (best < 0 || b.material_triangles[m] > b.material_triangles[best] ||
        (b.material_triangles[m] == b.material_triangles[best] &&
         b.material_first_use[m] < b.material_first_use[best]))
      best = static_cast<int>(m);
  }
  Material mat;
  if (best < 0) return mat;
  const tinyobj::material_t& t = b.materials[static_cast<size_t>(best)];
  // The scene JSON's rules for a material: colours and shininess finite, >= 0.
  for (const double c :
       {double(t.diffuse[0]), double(t.diffuse[1]), double(t.diffuse[2]), double(t.specular[0]),
        double(t.specular[1]), double(t.specular[2]), double(t.shininess)})
    if (!(std::isfinite(c) && c >= 0.0))
      throw InputError(b.mesh.name,
                       "material '" + t.name + "': Kd, Ks and Ns must be finite and >= 0");
  mat.diffuse = Vec3f(float(t.diffuse[0]), float(t.diffuse[1]), float(t.diffuse[2]));
  mat.specular = Vec3f(float(t.specular[0]), float(t.specular[1]), float(t.specular[2]));
  mat.shininess = float(t.shininess);
  return mat;
}

// Per-position normals from per-face-vertex ones (policy in obj_reader.h).
std::vector<Vec3f> position_normals(const ObjBuild& b) {
  const size_t nv = b.mesh.positions.size();
  constexpr int64_t kUnused = -1, kMixed = -2;
  std::vector<int64_t> which(nv, kUnused);
  for (const auto& [v, n] : b.vertex_normal) {
    if (which[v] == kUnused)
      which[v] = n;
    else if (which[v] != int64_t(n))
      which[v] = kMixed;
  }
  std::vector<Vec3f> out(nv, Vec3f(0.0f));
  for (const auto& [v, n] : b.vertex_normal) {
    if (which[v] != kMixed) continue;
    const Vec3f& d = b.vn[n];
    const float len = length(d);
    if (len > 0.0f && std::isfinite(len)) out[v] += d / len;
  }
  for (size_t v = 0; v < nv; ++v) {
    if (which[v] >= 0) {
      out[v] = b.vn[static_cast<size_t>(which[v])];
    } else if (which[v] == kMixed) {
      const float len = length(out[v]);
      if (len > 0.0f) out[v] = out[v] / len;
    }
  }
  return out;
}

}  // namespace

TriangleMesh read_obj(const std::string& path, std::string_view text) {
  const ObjTextSummary summary = validate_obj_text(path, text);

  ObjBuild b;
  b.mesh.name = path;
  b.mesh.positions.reserve(summary.vertices + 1);  // +1: pad_for_embree() needs no copy
  b.mesh.triangles.reserve(summary.triangles);
  b.vn.reserve(summary.normals);
  if (summary.normals > 0) b.vertex_normal.reserve(summary.triangles + 2 * summary.faces);

  tinyobj::callback_t cb;
  cb.vertex_cb = on_vertex;
  cb.normal_cb = on_normal;
  cb.index_cb = on_face;
  cb.usemtl_cb = on_usemtl;
  cb.mtllib_cb = on_mtllib;

  const size_t slash = path.find_last_of('/');
  MtlReader mtl_reader(slash == std::string::npos ? std::string("./") : path.substr(0, slash + 1));
  MemoryBuf buf(text);
  std::istream in(&buf);
  std::string warn, err;
  const bool ok = tinyobj::LoadObjWithCallback(in, cb, &b, &mtl_reader, &warn, &err);
  // Material problems (missing .mtl, unknown name) are warnings: default material.
  if (!ok) throw InputError(path, "tinyobjloader: " + err.substr(0, err.find('\n')));
  if (b.bad_index || b.mesh.positions.size() != summary.vertices ||
      b.mesh.triangles.size() != summary.triangles)
    throw InputError(path, "OBJ parse disagrees with the syntax check (unsupported OBJ variant)");

  for (const auto& [v, p] : summary.non_finite_vertices) b.mesh.positions[v] = p;
  if (summary.normals > 0 && b.every_vertex_has_normal && !b.mesh.triangles.empty())
    b.mesh.normals = position_normals(b);
  b.mesh.material = chosen_material(b);
  return std::move(b.mesh);
}

}  // namespace hprt
