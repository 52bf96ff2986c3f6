// Pinhole camera with a physical lens description: focal length and sensor
// width in millimetres set the field of view (hfov = 2 atan(sensor / 2f)).
#pragma once

#include "core/ray.h"
#include "core/vec.h"

namespace hprt {

// The lens values a camera may have (scene files and --focal alike): the
// range in which its rays stay finite and its image is not one pixel of
// background; positions within kMaxCameraCoordinate of the origin, whose
// rays are valid (core/ray.h's FLT_LARGE bound, with room for the scene).
inline constexpr float kMinLensMm = 0.1f;
inline constexpr float kMaxLensMm = 100000.0f;
inline constexpr float kMaxCameraCoordinate = 1e18f;
// Pixels of one image at most (a scene's camera, --width x --height).
inline constexpr long long kMaxCameraPixels = 16384LL * 16384;

struct Camera {
  Vec3f position{0.0f, 0.0f, 5.0f};
  Vec3f look_at{0.0f, 0.0f, 0.0f};
  Vec3f up{0.0f, 1.0f, 0.0f};
  float focal_length_mm = 35.0f;
  float sensor_width_mm = 36.0f;
  int width = 800;
  int height = 600;
};

// Precomputed camera frame; primary rays go through pixel centres, row 0 at
// the top. Set up in double so a camera far from the origin keeps its basis.
class CameraRays {
 public:
  explicit CameraRays(const Camera& cam) {
    const Vec3d pos(cam.position), at(cam.look_at), up(cam.up);
    const Vec3d fwd = normalize(at - pos);
    const Vec3d right = normalize(cross(fwd, up));
    const Vec3d true_up = cross(right, fwd);
    const double sensor_h = double(cam.sensor_width_mm) * cam.height / cam.width;
    org_ = cam.position;
    width_ = cam.width;
    height_ = cam.height;
    // Direction = fwd * focal + right * sx + up * sy, all in millimetres.
    fwd_ = Vec3f(fwd * double(cam.focal_length_mm));
    du_ = Vec3f(right * (double(cam.sensor_width_mm) / cam.width));
    dv_ = Vec3f(true_up * (-sensor_h / cam.height));
    corner_ = Vec3f(fwd * double(cam.focal_length_mm) - right * (0.5 * cam.sensor_width_mm) +
                    true_up * (0.5 * sensor_h));
  }

  // Ray through image position (px, py) in pixels, (0,0) the top-left corner.
  Ray ray(float px, float py) const {
    Ray r;
    r.org = org_;
    r.dir = normalize(corner_ + du_ * px + dv_ * py);
    r.tnear = 0.0f;
    return r;
  }
  Ray pixel_ray(int x, int y) const { return ray(float(x) + 0.5f, float(y) + 0.5f); }
  Vec3f forward() const { return normalize(fwd_); }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  Vec3f org_, fwd_, du_, dv_, corner_;
  int width_ = 0, height_ = 0;
};

}  // namespace hprt
