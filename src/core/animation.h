// Animation description from the scene file: frame count, rate, deformers
// applied to meshes' rest poses, or per-frame mesh files.
#pragma once

#include <string>
#include <vector>

#include "core/vec.h"

namespace hprt {

struct DeformerSpec {
  int mesh = 0;
  std::string kind;  // twist | bend | wave | pulse | explode
  float amplitude = 0.1f;
  float wavelength = 1.0f;
  float speed = 1.0f;
  float angle_deg = 90.0f;  // twist and bend: angle reached at t = 1 s
  int axis = 1;             // twist and bend: 0 = x, 1 = y, 2 = z
};

struct FrameSequenceSpec {
  int mesh = 0;
  std::string pattern;  // printf-style path, e.g. "frames/cloth_%04d.ply"
  int first = 0;
  // The mesh entry's placement (io/scene/scene_transform.h), applied to every frame
  // file as to the mesh itself; filled by the scene reader.
  Vec3f scale{1.0f, 1.0f, 1.0f};
  Vec3f rotate_deg{0.0f, 0.0f, 0.0f};
  Vec3f translate{0.0f, 0.0f, 0.0f};
};

struct Animation {
  int frames = 1;
  float fps = 24.0f;
  std::vector<DeformerSpec> deformers;
  std::vector<FrameSequenceSpec> sequences;
  bool animated() const { return !deformers.empty() || !sequences.empty(); }
};

}  // namespace hprt
