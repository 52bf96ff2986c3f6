// Pinhole camera: the optical axis lands in the image centre, a longer lens
// sees a narrower field, and the pixel grid keeps the image's aspect ratio.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/camera.h"

namespace hprt {
namespace {

Camera test_camera(float focal_mm, int w, int h) {
  Camera c;
  c.position = Vec3f(1.0f, 2.0f, 3.0f);
  c.look_at = Vec3f(4.0f, 1.0f, -5.0f);
  c.up = Vec3f(0.0f, 1.0f, 0.0f);
  c.focal_length_mm = focal_mm;
  c.sensor_width_mm = 36.0f;
  c.width = w;
  c.height = h;
  return c;
}

double angle_between(const Vec3f& a, const Vec3f& b) {
  const Vec3d da = normalize(Vec3d(a)), db = normalize(Vec3d(b));
  return std::acos(std::clamp(dot(da, db), -1.0, 1.0));
}

TEST(Camera, OpticalAxisHitsImageCentre) {
  const Camera cam = test_camera(13.0f, 801, 601);  // odd: a pixel centre at the centre
  const CameraRays rays(cam);
  const Vec3f axis = normalize(cam.look_at - cam.position);
  const Ray centre = rays.pixel_ray(400, 300);
  EXPECT_LT(angle_between(centre.dir, axis), 1e-6);
  EXPECT_EQ(centre.org, cam.position);
  // Even sizes: the image centre is the corner shared by four pixels.
  const CameraRays even(test_camera(13.0f, 800, 600));
  EXPECT_LT(angle_between(even.ray(400.0f, 300.0f).dir, axis), 1e-6);
  EXPECT_LT(angle_between(rays.forward(), axis), 1e-6);
}

TEST(Camera, HorizontalFieldOfViewFollowsFocalLength) {
  for (const float f : {6.0f, 13.0f, 35.0f}) {
    const CameraRays rays(test_camera(f, 800, 600));
    const double hfov = angle_between(rays.ray(0.0f, 300.0f).dir, rays.ray(800.0f, 300.0f).dir);
    EXPECT_NEAR(hfov, 2.0 * std::atan(36.0 / (2.0 * f)), 1e-5) << "focal " << f;
  }
}

TEST(Camera, LongerLensSeesNarrowerField) {
  const CameraRays wide(test_camera(6.0f, 800, 600));
  const CameraRays narrow(test_camera(13.0f, 800, 600));
  const Vec3f axis = wide.forward();
  // Corner rays: the 13 mm lens's corners are closer to the axis.
  const double wide_corner = angle_between(wide.ray(0.0f, 0.0f).dir, axis);
  const double narrow_corner = angle_between(narrow.ray(0.0f, 0.0f).dir, axis);
  EXPECT_GT(wide_corner, narrow_corner);
  // Exact diagonal half-angles: atan(half diagonal / f), sensor 36 x 27 mm.
  EXPECT_NEAR(wide_corner, std::atan(22.5 / 6.0), 1e-5);
  EXPECT_NEAR(narrow_corner, std::atan(22.5 / 13.0), 1e-5);
}

TEST(Camera, AspectRatioRespected) {
  // Square pixels: the vertical field is the horizontal one scaled by h/w.
  for (const auto& [w, h] : {std::pair{800, 600}, std::pair{1920, 1080}, std::pair{300, 400}}) {
    const Camera cam = test_camera(13.0f, w, h);
    const CameraRays rays(cam);
    const double hfov =
        angle_between(rays.ray(0.0f, h * 0.5f).dir, rays.ray(float(w), h * 0.5f).dir);
    const double vfov =
        angle_between(rays.ray(w * 0.5f, 0.0f).dir, rays.ray(w * 0.5f, float(h)).dir);
    const double sensor_h = 36.0 * h / w;
    EXPECT_NEAR(hfov, 2.0 * std::atan(18.0 / 13.0), 1e-5);
    EXPECT_NEAR(vfov, 2.0 * std::atan(sensor_h / 26.0), 1e-5);
    // Row 0 is the top: its rays point further along `up` than the last row's.
    EXPECT_GT(dot(rays.pixel_ray(w / 2, 0).dir, cam.up),
              dot(rays.pixel_ray(w / 2, h - 1).dir, cam.up));
    // Column 0 is the left: right = forward x up.
    const Vec3f right = cross(rays.forward(), cam.up);
    EXPECT_LT(dot(rays.pixel_ray(0, h / 2).dir, right),
              dot(rays.pixel_ray(w - 1, h / 2).dir, right));
  }
}

}  // namespace
}  // namespace hprt
