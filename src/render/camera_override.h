// A scene camera with the image size and lens a caller asks for (the CLI's
// --width/--height/--focal, the public API's render()): 0 keeps the scene's
// value, and one of width/height alone keeps the scene's aspect ratio.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "core/camera.h"
#include "core/error.h"

namespace hprt {

inline Camera override_camera(const Camera& scene_camera, int width, int height, float focal_mm) {
  Camera c = scene_camera;
  const double aspect = double(scene_camera.height) / double(scene_camera.width);
  if (width > 0) c.width = width;
  if (height > 0) c.height = height;
  if (width > 0 && height == 0) c.height = std::max(1, int(std::lround(width * aspect)));
  if (height > 0 && width == 0) c.width = std::max(1, int(std::lround(height / aspect)));
  if (focal_mm > 0.0f) c.focal_length_mm = focal_mm;
  if (static_cast<long long>(c.width) * c.height > kMaxCameraPixels)
    throw InputError("width, height", std::to_string(c.width) + "x" + std::to_string(c.height) +
                                          " is more than 16384x16384 pixels");
  return c;
}

}  // namespace hprt
