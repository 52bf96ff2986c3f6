// Scene loading: a JSON scene file (docs/ARCHITECTURE.md "Files") or a bare mesh path
// (OBJ/PLY, optionally .gz), which becomes a scene with a camera framing the
// mesh's bounding sphere and a head light. Throws InputError "path: problem".
#pragma once

#include <string>

#include "core/scene.h"

namespace hprt {

Scene load_scene(const std::string& path);

// Camera that frames `bounds` (its bounding sphere) from +z with the given
// lens, and a point light at the camera ("head light").
Camera framing_camera(const AABB& bounds, const Camera& lens);
Light head_light(const Camera& camera);

}  // namespace hprt
