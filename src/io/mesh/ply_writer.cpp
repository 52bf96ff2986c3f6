// PLY output: float x y z (+ nx ny nz), faces as `list uchar int
// vertex_indices`; ASCII floats use std::to_chars' shortest round-trip form,
// so reading the file back gives the same bits.
#include "io/mesh/ply_writer.h"

#include <bit>
#include <charconv>
#include <cstring>
#include <limits>

#include "core/error.h"
#include "io/files/atomic_file.h"

namespace hprt {
namespace {

template <typename T>
void put_binary(std::string& out, T v, bool swap) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof v);
  if (swap)
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  out.append(b, sizeof b);
}

void put_text(std::string& out, float v) {
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, v);
  out.append(b, r.ptr);
}

void put_text(std::string& out, uint32_t v) {
  char b[16];
  const auto r = std::to_chars(b, b + sizeof b, v);
  out.append(b, r.ptr);
}

}  // namespace

void write_ply(const TriangleMesh& mesh, const std::string& path, PlyFormat format) {
  if (mesh.positions.size() > size_t(std::numeric_limits<int32_t>::max()))
    throw InputError(path, "too many vertices for PLY int indices");
  const bool normals = !mesh.normals.empty() && mesh.normals.size() == mesh.positions.size();
  std::string out;
  out += "ply\nformat ";
  out += format == PlyFormat::kAscii                ? "ascii"
         : format == PlyFormat::kBinaryLittleEndian ? "binary_little_endian"
                                                    : "binary_big_endian";
  out += " 1.0\ncomment written by hprt\nelement vertex " + std::to_string(mesh.positions.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  out += "element face " + std::to_string(mesh.triangles.size()) +
         "\nproperty list uchar int vertex_indices\nend_header\n";

  if (format == PlyFormat::kAscii) {
    out.reserve(out.size() + mesh.positions.size() * (normals ? 80 : 40) +
                mesh.triangles.size() * 30);
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        if (k) out += ' ';
        put_text(out, mesh.positions[i][k]);
      }
      if (normals)
        for (int k = 0; k < 3; ++k) {
          out += ' ';
          put_text(out, mesh.normals[i][k]);
        }
      out += '\n';
    }
    for (const Vec3u& t : mesh.triangles) {
      out += '3';
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        put_text(out, t[k]);
      }
      out += '\n';
    }
  } else {
    const bool big = format == PlyFormat::kBinaryBigEndian;
    const bool swap = big != (std::endian::native == std::endian::big);
    out.reserve(out.size() + mesh.positions.size() * (normals ? 24 : 12) +
                mesh.triangles.size() * 13);
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) put_binary(out, mesh.positions[i][k], swap);
      if (normals)
        for (int k = 0; k < 3; ++k) put_binary(out, mesh.normals[i][k], swap);
    }
    for (const Vec3u& t : mesh.triangles) {
      out += char(3);
      for (int k = 0; k < 3; ++k) put_binary(out, static_cast<int32_t>(t[k]), swap);
    }
  }
  write_file_atomic(path, out.data(), out.size());
}

}  // namespace hprt
