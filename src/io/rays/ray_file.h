// .rays, .hits and occlusion files (docs/ARCHITECTURE.md "Files"): raw little-endian
// records, no header. .rays: 32 bytes per ray (== Ray); .hits: 20 bytes per
// ray (== Hit); occlusion: one byte per ray, 1 = occluded; counts (the count
// query): one uint32 per ray; hit lists (the all query): per ray a uint32
// count, then that many .hits records. .points (the point queries' input):
// 12 bytes per point, float32 x, y, z; locations (the inside query): one
// byte per point, 0 outside, 1 inside, 2 on the surface; closest points: 32
// bytes per point (== ClosestPoint).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/hit.h"
#include "core/hit_lists.h"
#include "core/point_query.h"
#include "core/ray.h"

namespace hprt {

// Readers throw InputError("path: problem") for a missing or unreadable file,
// a size that is not a whole number of records, or a file above 16 GiB.
std::vector<Ray> read_rays(const std::string& path);
std::vector<Hit> read_hits(const std::string& path);
std::vector<uint8_t> read_occlusion(const std::string& path);
std::vector<uint32_t> read_counts(const std::string& path);
// Also refuses a count that runs past the end of the file.
HitLists read_hit_lists(const std::string& path);
std::vector<Vec3f> read_points(const std::string& path);
// Also refuses a byte other than 0, 1 or 2.
std::vector<PointLocation> read_locations(const std::string& path);
std::vector<ClosestPoint> read_closest(const std::string& path);

// Writers are atomic (write_file_atomic): the file appears whole or not at all.
void write_rays(const std::string& path, std::span<const Ray> rays);
void write_hits(const std::string& path, std::span<const Hit> hits);
void write_occlusion(const std::string& path, std::span<const uint8_t> occluded);
void write_counts(const std::string& path, std::span<const uint32_t> counts);
void write_hit_lists(const std::string& path, const HitLists& lists);
void write_points(const std::string& path, std::span<const Vec3f> points);
void write_locations(const std::string& path, std::span<const PointLocation> locations);
void write_closest(const std::string& path, std::span<const ClosestPoint> closest);

}  // namespace hprt
