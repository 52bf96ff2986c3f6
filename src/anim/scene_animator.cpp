// SceneAnimator: per-mesh set-up (rest pose, unwelding for explode, vertex ->
// triangle adjacency for normals) once; then frame k = deformers at
// t = k / fps chained in place over the rest pose, or frame file first + k.
#include "anim/scene_animator.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>

#include "anim/deformers.h"
#include "core/error.h"
#include "core/frame_pattern.h"
#include "io/mesh/mesh_reader.h"
#include "io/scene/scene_transform.h"

namespace hprt {

struct AnimatedMesh {
  size_t index = 0;  // in scene.meshes
  std::vector<Vec3f> rest;
  RestPose pose;
  std::vector<DeformerSpec> deformers;  // applied in order
  std::optional<FrameSequenceSpec> sequence;
  // Normal recomputation (only when the mesh has normals): the triangles
  // around each vertex in CSR form, and the rest normals as the fallback for a
  // vertex whose triangles all have zero area.
  std::vector<size_t> ring_begin;  // vertex count + 1
  std::vector<uint32_t> ring;
  std::vector<Vec3f> rest_normals;
};

namespace {

std::string mesh_label(size_t i) { return "animation: mesh " + std::to_string(i); }

void check_deformer(const DeformerSpec& d, size_t mesh) {
  static const char* kinds[] = {"twist", "bend", "wave", "pulse", "explode"};
  if (std::find(std::begin(kinds), std::end(kinds), d.kind) == std::end(kinds))
    throw InputError(mesh_label(mesh), "unknown deformer '" + d.kind + "'");
  if (d.axis < 0 || d.axis > 2)
    throw InputError(mesh_label(mesh), d.kind + ": axis must be 0, 1 or 2");
  if (!(d.wavelength > 0.0f)) throw InputError(mesh_label(mesh), d.kind + ": wavelength <= 0");
}

void build_rings(const TriangleMesh& mesh, AnimatedMesh& a) {
  const size_t nv = mesh.positions.size();
  a.ring_begin.assign(nv + 1, 0);
  for (const Vec3u& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] < nv) ++a.ring_begin[t[k] + 1];
  for (size_t v = 0; v < nv; ++v) a.ring_begin[v + 1] += a.ring_begin[v];
  a.ring.resize(a.ring_begin[nv]);
  std::vector<size_t> fill(a.ring_begin.begin(), a.ring_begin.end() - 1);
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (mesh.triangles[i][k] < nv) a.ring[fill[mesh.triangles[i][k]]++] = uint32_t(i);
  a.rest_normals = mesh.normals;
}

// Area-weighted vertex normals from the current positions, in a fixed order
// per vertex (the same bits for any thread count).
void recompute_normals(const AnimatedMesh& a, TriangleMesh& mesh) {
  const size_t nv = mesh.positions.size();
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
          Vec3f n(0.0f);
          for (size_t j = a.ring_begin[v]; j < a.ring_begin[v + 1]; ++j) {
            const Vec3u& t = mesh.triangles[a.ring[j]];
            if (t[0] >= nv || t[1] >= nv || t[2] >= nv) continue;
            const Vec3f& p0 = mesh.positions[t[0]];
            n += cross(mesh.positions[t[1]] - p0, mesh.positions[t[2]] - p0);
          }
          const float len = length(n);
          mesh.normals[v] = len > 0.0f && std::isfinite(len) ? n / len : a.rest_normals[v];
        }
      });
}

// Frame file `path` loaded and placed like the mesh; its topology must be the mesh's.
TriangleMesh load_frame_mesh(const std::string& path, const FrameSequenceSpec& s,
                             const TriangleMesh& mesh) {
  TriangleMesh f = load_mesh(path);
  if (f.positions.size() != mesh.positions.size() || f.triangles.size() != mesh.triangles.size())
    throw InputError(path, std::to_string(f.positions.size()) + " vertices and " +
                               std::to_string(f.triangles.size()) + " triangles, but mesh " +
                               std::to_string(s.mesh) + " has " +
                               std::to_string(mesh.positions.size()) + " and " +
                               std::to_string(mesh.triangles.size()) +
                               " (a frame sequence must keep the topology)");
  if (f.triangles != mesh.triangles) {
    size_t i = 0;
    while (f.triangles[i] == mesh.triangles[i]) ++i;
    throw InputError(path, "triangle " + std::to_string(i) +
                               " has other vertex indices than in mesh " + std::to_string(s.mesh) +
                               " (a frame sequence must keep the topology)");
  }
  MeshTransform t;
  t.scale = s.scale;
  t.rotate_deg = s.rotate_deg;
  t.translate = s.translate;
  apply_transform(f, t);
  return f;
}

}  // namespace

SceneAnimator::SceneAnimator(Scene& scene) {
  const Animation& anim = scene.animation;
  frames_ = anim.frames;
  fps_ = anim.fps;
  if (frames_ < 1) throw InputError("animation.frames", "must be at least 1");
  if (!(fps_ > 0.0f)) throw InputError("animation.fps", "must be positive");
  std::vector<std::unique_ptr<AnimatedMesh>> by_mesh(scene.meshes.size());
  auto entry = [&](int mesh) -> AnimatedMesh& {
    if (mesh < 0 || size_t(mesh) >= scene.meshes.size())
      throw InputError("animation", "mesh " + std::to_string(mesh) + " does not exist (" +
                                        std::to_string(scene.meshes.size()) + " meshes)");
    auto& a = by_mesh[size_t(mesh)];
    if (!a) {
      a = std::make_unique<AnimatedMesh>();
      a->index = size_t(mesh);
    }
    return *a;
  };
  for (const DeformerSpec& d : anim.deformers) {
    check_deformer(d, size_t(std::max(d.mesh, 0)));
    entry(d.mesh).deformers.push_back(d);
  }
  for (const FrameSequenceSpec& s : anim.sequences) {
    AnimatedMesh& a = entry(s.mesh);
    if (a.sequence) throw InputError(mesh_label(a.index), "has two frame sequences");
    if (!a.deformers.empty())
      throw InputError(mesh_label(a.index), "has both a frame sequence and deformers");
    if (!has_frame_number(s.pattern, s.pattern) && frames_ > 1)
      throw InputError(s.pattern, "a frame sequence pattern needs a %d conversion");
    a.sequence = s;
  }

  for (auto& a : by_mesh) {
    if (!a) continue;
    TriangleMesh& mesh = scene.meshes[a->index];
    const bool explodes = std::any_of(a->deformers.begin(), a->deformers.end(),
                                      [](const DeformerSpec& d) { return d.kind == "explode"; });
    if (explodes && !is_unwelded(mesh)) unweld(mesh);
    mesh.pad_for_embree();
    if (a->sequence) {
      for (int k = 0; k < frames_; ++k) {  // all files present; frame 0 read in full
        const std::string path = format_frame_path(a->sequence->pattern, a->sequence->first + k);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec))
          throw InputError(path, "frame " + std::to_string(k) + " of mesh " +
                                     std::to_string(a->index) + "'s sequence does not exist");
      }
      load_frame_mesh(format_frame_path(a->sequence->pattern, a->sequence->first), *a->sequence,
                      mesh);
    }
    a->rest = std::as_const(mesh).positions.to_vector();
    a->pose = measure_rest_pose(a->rest);
    if (!mesh.normals.empty() && mesh.normals.size() == mesh.positions.size())
      build_rings(mesh, *a);
    meshes_.push_back(std::move(a));
  }
}

SceneAnimator::~SceneAnimator() = default;
SceneAnimator::SceneAnimator(SceneAnimator&&) noexcept = default;
SceneAnimator& SceneAnimator::operator=(SceneAnimator&&) noexcept = default;

void SceneAnimator::apply(int frame, Scene& scene) const {
  if (frame < 0 || frame >= frames_)
    throw InputError("frame " + std::to_string(frame),
                     "outside the animation (frames 0 to " + std::to_string(frames_ - 1) + ")");
  const float t = float(double(frame) / double(fps_));
  for (const auto& a : meshes_) {
    if (a->index >= scene.meshes.size() ||
        scene.meshes[a->index].positions.size() != a->rest.size())
      throw InputError(mesh_label(a->index), "the scene does not match the animator's set-up");
    TriangleMesh& mesh = scene.meshes[a->index];
    std::span<Vec3f> out(mesh.positions);
    if (a->sequence) {
      const std::string path = format_frame_path(a->sequence->pattern, a->sequence->first + frame);
      const TriangleMesh f = load_frame_mesh(path, *a->sequence, mesh);
      std::copy(f.positions.begin(), f.positions.end(), mesh.positions.begin());
    } else {
      std::span<const Vec3f> in(a->rest);
      for (const DeformerSpec& d : a->deformers) {
        apply_deformer(d, a->pose, t, in, out);
        in = out;
      }
      if (a->deformers.empty()) std::copy(a->rest.begin(), a->rest.end(), out.begin());
    }
    if (!a->ring_begin.empty()) recompute_normals(*a, mesh);
  }
}

}  // namespace hprt
