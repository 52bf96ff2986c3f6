// Frame k of a scene's animation (core/animation.h): deformers applied to each
// mesh's rest pose at t = k / fps, or mesh k of a per-frame file sequence,
// written into the scene's vertex buffers in place. Frame k depends only on k.
#pragma once

#include <memory>
#include <vector>

#include "core/scene.h"

namespace hprt {

struct AnimatedMesh;  // rest pose and per-mesh set-up (scene_animator.cpp)

class SceneAnimator {
 public:
  // Prepares `scene` (unwelds meshes with an explode deformer, checks per-frame
  // file sequences: every frame file exists, and the first has the mesh's
  // vertex/triangle counts and topology, else InputError naming the file) and
  // captures the rest pose of every animated mesh.
  explicit SceneAnimator(Scene& scene);
  ~SceneAnimator();
  SceneAnimator(SceneAnimator&&) noexcept;
  SceneAnimator& operator=(SceneAnimator&&) noexcept;

  int frames() const { return frames_; }  // scene.animation.frames
  bool animated() const { return !meshes_.empty(); }
  float fps() const { return fps_; }

  // Writes frame k's vertex positions (and recomputed normals if the mesh has
  // normals) into `scene`, in place: same vector sizes, so buffers shared with
  // Embree stay valid. Depends only on k. Throws InputError for a bad frame
  // file or a frame outside [0, frames()). Runs in parallel in the caller's
  // task arena; deformers allocate nothing per frame.
  void apply(int frame, Scene& scene) const;

 private:
  int frames_ = 1;
  float fps_ = 24.0f;
  std::vector<std::unique_ptr<AnimatedMesh>> meshes_;
};

}  // namespace hprt
