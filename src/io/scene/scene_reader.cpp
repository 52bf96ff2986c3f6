// Scene loading (docs/ARCHITECTURE.md "Files"): a strict reader for the JSON schema
// (unknown fields and wrong types are errors naming their JSON path), or a
// bare mesh path framed by a default camera with a head light.
// Defaults beyond src/core/*.h: a file without "camera" gets the framing
// camera of its meshes (default lens), and one without "lights" a head light;
// "lights": [] means no lights.
#include "io/scene/scene_reader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <utility>

#include "core/error.h"
#include "core/frame_pattern.h"
#include "io/files/file_bytes.h"
#include "io/mesh/generate_mesh.h"
#include "io/mesh/mesh_reader.h"
#include "io/scene/scene_json.h"
#include "io/scene/scene_transform.h"

namespace hprt {
namespace {

constexpr size_t kMaxSceneBytes = size_t{64} << 20;
constexpr int kMaxDepth = 64;
constexpr int64_t kMaxFrames = 1'000'000;

struct MaterialOverride {
  std::optional<Vec3f> diffuse, specular;
  std::optional<float> shininess, reflectivity;
  void apply(Material& m) const {
    if (diffuse) m.diffuse = *diffuse;
    if (specular) m.specular = *specular;
    if (shininess) m.shininess = *shininess;
    if (reflectivity) m.reflectivity = *reflectivity;
  }
};

struct MeshEntry {
  std::string file;  // resolved; empty when generated
  std::optional<GenerateSpec> generate;
  MeshTransform transform;
  MaterialOverride material;
};

// Reads a scene file once, field by field, into a Scene (meshes last).
class SceneParser {
 public:
  SceneParser(const std::string& path) : path_(path) {
    dir_ = std::filesystem::path(path).parent_path();
  }

  Scene parse(const Json& root) {
    JsonObject top(path_, root, "");
    Scene scene;
    std::optional<Camera> camera;
    if (const Json* j = top.find("camera")) camera = read_camera(*j);
    if (const Json* j = top.find("background")) scene.background = non_negative(*j, "background");
    if (const Json* j = top.find("ambient")) scene.ambient = non_negative(*j, "ambient");
    if (const Json* j = top.find("max_depth"))
      scene.max_depth = int(integer_in(*j, "max_depth", 0, kMaxDepth));
    std::optional<std::vector<Light>> lights;
    if (const Json* j = top.find("lights")) lights = read_lights(*j);
    const Json* meshes = top.find("meshes");
    if (!meshes) throw InputError(path_, "missing field 'meshes' (an array of meshes)");
    std::vector<MeshEntry> entries;
    const Json& list = json_array(path_, *meshes, "meshes");
    for (size_t i = 0; i < list.size(); ++i)
      entries.push_back(read_mesh(list[i], index("meshes", i)));
    if (const Json* j = top.find("animation")) scene.animation = read_animation(*j, entries.size());
    top.finish();
    for (FrameSequenceSpec& s : scene.animation.sequences) {  // frame files placed as the mesh
      const MeshTransform& t = entries[size_t(s.mesh)].transform;
      s.scale = t.scale;
      s.rotate_deg = t.rotate_deg;
      s.translate = t.translate;
    }

    for (size_t i = 0; i < entries.size(); ++i) {
      const MeshEntry& e = entries[i];
      TriangleMesh mesh;
      try {
        mesh = e.generate ? generate_mesh(*e.generate) : load_mesh(e.file);
      } catch (const InputError& err) {  // keep the scene file and entry in the message
        throw InputError(path_, index("meshes", i) + ": " + err.what());
      }
      apply_transform(mesh, e.transform);
      e.material.apply(mesh.material);
      scene.add_mesh(std::move(mesh));
    }
    scene.camera = camera ? *camera : framing_camera(scene.bounds(), Camera{});
    scene.lights = lights ? *lights : std::vector<Light>{head_light(scene.camera)};
    return scene;
  }

 private:
  static std::string index(const std::string& path, size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }
  std::string resolve(const std::string& file) const {
    const std::filesystem::path p(file);
    return p.is_relative() && !dir_.empty() ? (dir_ / p).string() : file;
  }
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw_field_error(path_, field, problem);
  }
  float lens_mm(const Json& j, const std::string& field) const {
    const float v = json_float(path_, j, field);
    if (!(v >= kMinLensMm && v <= kMaxLensMm))
      fail(field, "must be in [0.1, 100000] mm, got " + j.dump());
    return v;
  }
  float positive(const Json& j, const std::string& field) const {
    const float v = json_float(path_, j, field);
    if (!(v > 0.0f)) fail(field, "must be positive, got " + j.dump());
    return v;
  }
  float non_negative_number(const Json& j, const std::string& field) const {
    const float v = json_float(path_, j, field);
    if (v < 0.0f) fail(field, "must not be negative, got " + j.dump());
    return v;
  }
  Vec3f non_negative(const Json& j, const std::string& field) const {
    const Vec3f v = json_vec3(path_, j, field);
    if (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f) fail(field, "components must not be negative");
    return v;
  }
  int64_t integer_in(const Json& j, const std::string& field, int64_t lo, int64_t hi) const {
    const int64_t v = json_integer(path_, j, field);
    if (v < lo || v > hi)
      fail(field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                      std::to_string(v));
    return v;
  }

  Camera read_camera(const Json& j) {
    JsonObject o(path_, j, "camera");
    Camera c;
    if (const Json* v = o.find("position")) c.position = json_vec3(path_, *v, o.field("position"));
    if (const Json* v = o.find("look_at")) c.look_at = json_vec3(path_, *v, o.field("look_at"));
    if (const Json* v = o.find("up")) c.up = json_vec3(path_, *v, o.field("up"));
    if (const Json* v = o.find("focal_length_mm"))
      c.focal_length_mm = lens_mm(*v, o.field("focal_length_mm"));
    if (const Json* v = o.find("sensor_width_mm"))
      c.sensor_width_mm = lens_mm(*v, o.field("sensor_width_mm"));
    if (const Json* v = o.find("width"))
      c.width = int(integer_in(*v, o.field("width"), 1, kMaxCameraPixels));
    if (const Json* v = o.find("height"))
      c.height = int(integer_in(*v, o.field("height"), 1, kMaxCameraPixels));
    o.finish();
    if (int64_t(c.width) * c.height > kMaxCameraPixels)
      fail("camera.width", std::to_string(c.width) + "x" + std::to_string(c.height) +
                               " is more than 16384x16384 pixels");
    for (const auto& [field, p] :
         {std::pair{"camera.position", c.position}, std::pair{"camera.look_at", c.look_at}})
      if (!(std::fabs(p.x) <= kMaxCameraCoordinate && std::fabs(p.y) <= kMaxCameraCoordinate &&
            std::fabs(p.z) <= kMaxCameraCoordinate))
        fail(field, "components must be within +-1e18");
    const Vec3d fwd = Vec3d(c.look_at) - Vec3d(c.position);
    if (length(fwd) == 0.0) fail("camera.look_at", "equals camera.position");
    const Vec3d side = cross(normalize(fwd), Vec3d(c.up));
    if (!(length(side) > 1e-9)) fail("camera.up", "zero or parallel to the viewing direction");
    return c;
  }

  std::vector<Light> read_lights(const Json& j) {
    std::vector<Light> lights;
    for (size_t i = 0; i < json_array(path_, j, "lights").size(); ++i) {
      JsonObject o(path_, j[i], index("lights", i));
      Light l;
      if (const Json* v = o.find("type")) {
        const std::string type = json_string(path_, *v, o.field("type"));
        if (type == "point")
          l.type = LightType::kPoint;
        else if (type == "directional")
          l.type = LightType::kDirectional;
        else
          fail(o.field("type"), "unknown light type '" + type + "' (point or directional)");
      }
      if (l.type == LightType::kPoint) {
        if (const Json* v = o.find("position"))
          l.position = json_vec3(path_, *v, o.field("position"));
      } else if (const Json* v = o.find("direction")) {
        l.direction = json_vec3(path_, *v, o.field("direction"));
        if (l.direction == Vec3f(0.0f)) fail(o.field("direction"), "must not be zero");
      }
      if (const Json* v = o.find("intensity")) l.intensity = non_negative(*v, o.field("intensity"));
      o.finish();
      lights.push_back(l);
    }
    return lights;
  }

  MeshEntry read_mesh(const Json& j, const std::string& path) {
    JsonObject o(path_, j, path);
    MeshEntry e;
    const Json* file = o.find("file");
    const Json* gen = o.find("generate");
    if ((file != nullptr) == (gen != nullptr))
      fail(path, "needs exactly one of 'file' and 'generate'");
    if (file) {
      e.file = json_string(path_, *file, o.field("file"));
      if (e.file.empty()) fail(o.field("file"), "empty path");
      e.file = resolve(e.file);
    } else {
      e.generate = read_generate(*gen, o.field("generate"));
    }
    if (const Json* v = o.find("transform")) e.transform = read_transform(*v, o.field("transform"));
    if (const Json* v = o.find("material")) e.material = read_material(*v, o.field("material"));
    o.finish();
    return e;
  }

  GenerateSpec read_generate(const Json& j, const std::string& path) {
    JsonObject o(path_, j, path);
    GenerateSpec g;
    const Json* kind = o.find("kind");
    if (!kind) fail(path, "missing field 'kind'");
    g.kind = json_string(path_, *kind, o.field("kind"));
    const auto& kinds = generator_kinds();
    if (std::find(kinds.begin(), kinds.end(), g.kind) == kinds.end())
      fail(o.field("kind"), "unknown generator kind '" + g.kind + "'");
    if (const Json* v = o.find("tris"))
      g.tris = size_t(integer_in(*v, o.field("tris"), 1, int64_t(kMaxGenerateTriangles)));
    if (const Json* v = o.find("seed"))
      g.seed = uint64_t(integer_in(*v, o.field("seed"), 0, INT64_MAX));
    if (const Json* v = o.find("from")) {
      if (g.kind != "subdivide") fail(o.field("from"), "only used by kind 'subdivide'");
      g.from = json_string(path_, *v, o.field("from"));
      if (g.from.empty()) fail(o.field("from"), "empty path");
      g.from = resolve(g.from);
    } else if (g.kind == "subdivide") {
      fail(path, "kind 'subdivide' needs 'from' (the mesh to subdivide)");
    }
    o.finish();
    return g;
  }

  MeshTransform read_transform(const Json& j, const std::string& path) {
    JsonObject o(path_, j, path);
    MeshTransform t;
    if (const Json* v = o.find("scale")) {
      t.scale = v->is_number() ? Vec3f(json_float(path_, *v, o.field("scale")))
                               : json_vec3(path_, *v, o.field("scale"));
      if (t.scale.x == 0.0f || t.scale.y == 0.0f || t.scale.z == 0.0f)
        fail(o.field("scale"), "must not be zero");
    }
    if (const Json* v = o.find("rotate_deg"))
      t.rotate_deg = json_vec3(path_, *v, o.field("rotate_deg"));
    if (const Json* v = o.find("translate"))
      t.translate = json_vec3(path_, *v, o.field("translate"));
    o.finish();
    return t;
  }

  MaterialOverride read_material(const Json& j, const std::string& path) {
    JsonObject o(path_, j, path);
    MaterialOverride m;
    if (const Json* v = o.find("diffuse")) m.diffuse = non_negative(*v, o.field("diffuse"));
    if (const Json* v = o.find("specular")) m.specular = non_negative(*v, o.field("specular"));
    if (const Json* v = o.find("shininess"))
      m.shininess = non_negative_number(*v, o.field("shininess"));
    if (const Json* v = o.find("reflectivity")) {
      m.reflectivity = json_float(path_, *v, o.field("reflectivity"));
      if (*m.reflectivity < 0.0f || *m.reflectivity > 1.0f)
        fail(o.field("reflectivity"), "must be in [0, 1], got " + v->dump());
    }
    o.finish();
    return m;
  }

  Animation read_animation(const Json& j, size_t mesh_count) {
    JsonObject o(path_, j, "animation");
    Animation a;
    if (const Json* v = o.find("frames"))
      a.frames = int(integer_in(*v, o.field("frames"), 1, kMaxFrames));
    if (const Json* v = o.find("fps")) a.fps = positive(*v, o.field("fps"));
    const int64_t last_mesh = int64_t(mesh_count) - 1;
    if (const Json* v = o.find("deformers")) {
      const std::string list = o.field("deformers");
      for (size_t i = 0; i < json_array(path_, *v, list).size(); ++i) {
        JsonObject d(path_, (*v)[i], index(list, i));
        DeformerSpec s;
        if (const Json* x = d.find("mesh"))
          s.mesh = int(integer_in(*x, d.field("mesh"), 0, last_mesh));
        else if (mesh_count == 0)
          fail(d.field("mesh"), "the scene has no meshes");
        const Json* kind = d.find("kind");
        if (!kind) fail(index(list, i), "missing field 'kind'");
        s.kind = json_string(path_, *kind, d.field("kind"));
        static const std::vector<std::string> kinds{"twist", "bend", "wave", "pulse", "explode"};
        if (std::find(kinds.begin(), kinds.end(), s.kind) == kinds.end())
          fail(d.field("kind"),
               "unknown deformer '" + s.kind + "' (twist, bend, wave, pulse, explode)");
        if (const Json* x = d.find("amplitude"))
          s.amplitude = json_float(path_, *x, d.field("amplitude"));
        if (const Json* x = d.find("wavelength"))
          s.wavelength = positive(*x, d.field("wavelength"));
        if (const Json* x = d.find("speed")) s.speed = json_float(path_, *x, d.field("speed"));
        if (const Json* x = d.find("angle_deg"))
          s.angle_deg = json_float(path_, *x, d.field("angle_deg"));
        if (const Json* x = d.find("axis")) s.axis = read_axis(*x, d.field("axis"));
        d.finish();
        a.deformers.push_back(s);
      }
    }
    if (const Json* v = o.find("sequences")) {
      const std::string list = o.field("sequences");
      for (size_t i = 0; i < json_array(path_, *v, list).size(); ++i) {
        JsonObject q(path_, (*v)[i], index(list, i));
        FrameSequenceSpec s;
        if (const Json* x = q.find("mesh"))
          s.mesh = int(integer_in(*x, q.field("mesh"), 0, last_mesh));
        else if (mesh_count == 0)
          fail(q.field("mesh"), "the scene has no meshes");
        const Json* pattern = q.find("pattern");
        if (!pattern) fail(index(list, i), "missing field 'pattern'");
        s.pattern = json_string(path_, *pattern, q.field("pattern"));
        if (s.pattern.empty()) fail(q.field("pattern"), "empty pattern");
        // Checked here, naming the scene and the field, not first when an
        // animation is played.
        bool numbered = false;
        try {
          numbered = has_frame_number(s.pattern, q.field("pattern"));
        } catch (const InputError& e) {  // "field: 'pattern': problem"
          const std::string m = e.what();
          fail(q.field("pattern"), m.substr(m.find(": ") + 2));
        }
        if (!numbered && a.frames > 1)
          fail(q.field("pattern"), "'" + s.pattern +
                                       "' has no frame number (%d, %04d, ...) for the " +
                                       std::to_string(a.frames) + " frames");
        for (const FrameSequenceSpec& other : a.sequences)
          if (other.mesh == s.mesh)
            fail(index(list, i), "mesh " + std::to_string(s.mesh) + " has two frame sequences");
        for (const DeformerSpec& d : a.deformers)
          if (d.mesh == s.mesh)
            fail(index(list, i), "mesh " + std::to_string(s.mesh) +
                                     " has deformers too: a mesh is animated by one or the other");
        s.pattern = resolve(s.pattern);
        if (const Json* x = q.find("first"))
          s.first = int(integer_in(*x, q.field("first"), 0, INT32_MAX));
        q.finish();
        a.sequences.push_back(s);
      }
    }
    o.finish();
    return a;
  }

  // 0/1/2 or "x"/"y"/"z".
  int read_axis(const Json& j, const std::string& field) const {
    if (j.is_string()) {
      const std::string s = j.get<std::string>();
      if (s == "x") return 0;
      if (s == "y") return 1;
      if (s == "z") return 2;
      fail(field, "expected 0, 1, 2, \"x\", \"y\" or \"z\", got \"" + s + "\"");
    }
    return int(integer_in(j, field, 0, 2));
  }

  const std::string& path_;
  std::filesystem::path dir_;
};

}  // namespace

Camera framing_camera(const AABB& bounds, const Camera& lens) {
  Camera c = lens;
  Vec3d centre(0.0), extent(0.0);
  if (!bounds.empty()) {
    centre = (Vec3d(bounds.min) + Vec3d(bounds.max)) * 0.5;
    extent = Vec3d(bounds.max) - Vec3d(bounds.min);
  }
  double radius = 0.5 * length(extent);
  if (!(radius > 0.0)) radius = 1.0;  // empty scene or a single point
  const double sensor_h = double(lens.sensor_width_mm) * lens.height / lens.width;
  const double half_h = std::atan(0.5 * lens.sensor_width_mm / lens.focal_length_mm);
  const double half_v = std::atan(0.5 * sensor_h / lens.focal_length_mm);
  const double distance = radius / std::sin(std::min(half_h, half_v));
  const Vec3d dir = normalize(Vec3d(0.0, 0.25, 1.0));
  c.position = Vec3f(centre + dir * distance);
  c.look_at = Vec3f(centre);
  c.up = Vec3f(0.0f, 1.0f, 0.0f);
  return c;
}

Light head_light(const Camera& camera) {
  Light l;
  l.type = LightType::kPoint;
  l.position = camera.position;
  l.intensity = Vec3f(1.0f);
  return l;
}

Scene load_scene(const std::string& path) {
  if (mesh_extension(path) != ".json") {
    Scene scene;
    scene.add_mesh(load_mesh(path));
    scene.camera = framing_camera(scene.bounds(), Camera{});
    scene.lights.push_back(head_light(scene.camera));
    return scene;
  }
  const std::string bytes = read_file_bytes(path, kMaxSceneBytes);
  const Json root = parse_json(path, bytes);
  return SceneParser(path).parse(root);
}

}  // namespace hprt
