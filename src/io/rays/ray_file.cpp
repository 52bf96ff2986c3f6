// Raw record files for rays, hits and occlusion results (see ray_file.h). The
// in-memory structs are the file records, so reading is one fread.
#include "io/rays/ray_file.h"

#include <sys/stat.h>

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "core/error.h"
#include "io/files/atomic_file.h"

namespace hprt {
namespace {

static_assert(std::endian::native == std::endian::little,
              ".rays/.hits are little endian and read by memcpy");

constexpr unsigned long long kMaxFileBytes = 1ull << 34;  // 16 GiB: refuse anything larger

template <typename T>
std::vector<T> read_records(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw InputError(path, "not a regular file");
  const unsigned long long size = static_cast<unsigned long long>(st.st_size);
  if (size > kMaxFileBytes)
    throw InputError(path, "size " + std::to_string(size) + " is above the limit of " +
                               std::to_string(kMaxFileBytes) + " bytes");
  if (size % sizeof(T) != 0)
    throw InputError(path, "size " + std::to_string(size) + " is not a multiple of " +
                               std::to_string(sizeof(T)));
  std::vector<T> out(size / sizeof(T));
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  if (size && std::fread(out.data(), 1, size, f.get()) != size)
    throw InputError(path, "short read (file changed while reading?)");
  return out;
}

}  // namespace

std::vector<Ray> read_rays(const std::string& path) { return read_records<Ray>(path); }
std::vector<Hit> read_hits(const std::string& path) { return read_records<Hit>(path); }
std::vector<uint8_t> read_occlusion(const std::string& path) { return read_records<uint8_t>(path); }
std::vector<uint32_t> read_counts(const std::string& path) { return read_records<uint32_t>(path); }

std::vector<Vec3f> read_points(const std::string& path) {
  static_assert(sizeof(Vec3f) == 12);
  return read_records<Vec3f>(path);
}
std::vector<ClosestPoint> read_closest(const std::string& path) {
  return read_records<ClosestPoint>(path);
}
std::vector<PointLocation> read_locations(const std::string& path) {
  const std::vector<uint8_t> bytes = read_records<uint8_t>(path);
  std::vector<PointLocation> out(bytes.size());
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (bytes[i] > 2)
      throw InputError(path, "byte " + std::to_string(i) + " is " + std::to_string(bytes[i]) +
                                 ", not a location (0 outside, 1 inside, 2 on the surface)");
    out[i] = PointLocation(bytes[i]);
  }
  return out;
}

HitLists read_hit_lists(const std::string& path) {
  const std::vector<uint8_t> bytes = read_records<uint8_t>(path);
  HitLists out;
  out.offsets.push_back(0);
  size_t at = 0;
  while (at < bytes.size()) {
    if (bytes.size() - at < sizeof(uint32_t))
      throw InputError(path, "truncated count at byte " + std::to_string(at));
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + at, sizeof n);
    at += sizeof n;
    if (uint64_t(n) * sizeof(Hit) > bytes.size() - at)
      throw InputError(path, "count " + std::to_string(n) + " at byte " +
                                 std::to_string(at - sizeof n) + " runs past the end of the file");
    const size_t first = out.hits.size();
    out.hits.resize(first + n);
    std::memcpy(out.hits.data() + first, bytes.data() + at, size_t(n) * sizeof(Hit));
    at += size_t(n) * sizeof(Hit);
    out.offsets.push_back(out.hits.size());
    out.truncated.push_back(0);  // not stored in the file
  }
  return out;
}

void write_rays(const std::string& path, std::span<const Ray> rays) {
  write_file_atomic(path, rays.data(), rays.size_bytes());
}
void write_hits(const std::string& path, std::span<const Hit> hits) {
  write_file_atomic(path, hits.data(), hits.size_bytes());
}
void write_occlusion(const std::string& path, std::span<const uint8_t> occluded) {
  write_file_atomic(path, occluded.data(), occluded.size_bytes());
}
void write_counts(const std::string& path, std::span<const uint32_t> counts) {
  write_file_atomic(path, counts.data(), counts.size_bytes());
}
void write_points(const std::string& path, std::span<const Vec3f> points) {
  write_file_atomic(path, points.data(), points.size_bytes());
}
void write_locations(const std::string& path, std::span<const PointLocation> locations) {
  write_file_atomic(path, locations.data(), locations.size_bytes());
}
void write_closest(const std::string& path, std::span<const ClosestPoint> closest) {
  write_file_atomic(path, closest.data(), closest.size_bytes());
}
void write_hit_lists(const std::string& path, const HitLists& lists) {
  std::vector<uint8_t> bytes;
  bytes.reserve(lists.rays() * sizeof(uint32_t) + lists.hits.size() * sizeof(Hit));
  for (size_t i = 0; i < lists.rays(); ++i) {
    const uint32_t n = uint32_t(lists.count(i));
    const auto* c = reinterpret_cast<const uint8_t*>(&n);
    bytes.insert(bytes.end(), c, c + sizeof n);
    const auto* h = reinterpret_cast<const uint8_t*>(lists.begin(i));
    bytes.insert(bytes.end(), h, h + n * sizeof(Hit));
  }
  write_file_atomic(path, bytes.data(), bytes.size());
}

}  // namespace hprt
