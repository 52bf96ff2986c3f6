// write_ply: exact round trip through load_mesh in all three encodings, the
// header and byte layout, and atomic output.
#include "io/mesh/ply_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>

#include "core/error.h"
#include "io/mesh/mesh_reader.h"
#include "tests/support/cli_test_support.h"
#include "tests/support/io_test_files.h"

namespace fs = std::filesystem;
using hprt::PlyFormat;
using hprt::TriangleMesh;
using hprt::Vec3f;
using hprt::Vec3u;

namespace {

using hprt::test::slurp;

// A small grid with awkward floats (non-representable decimals, tiny, huge, NaN).
TriangleMesh grid(bool with_normals) {
  TriangleMesh m;
  const int n = 7;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      m.positions.push_back(
          Vec3f(x * 0.1f + 1e-7f * y, std::sin(float(x * y)) * 3e5f, 1.0f / 3 * y));
  m.positions[5].z = std::numeric_limits<float>::quiet_NaN();
  m.positions[6].y = -std::numeric_limits<float>::infinity();
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const uint32_t i = uint32_t(y * n + x);
      m.triangles.push_back(Vec3u{{i, i + 1, i + n + 1}});
      m.triangles.push_back(Vec3u{{i, i + n + 1, i + n}});
    }
  if (with_normals)
    for (size_t i = 0; i < m.positions.size(); ++i)
      m.normals.push_back(normalize(Vec3f(float(i % 3), 1.0f, float(i % 5) - 2)));
  return m;
}

// Bitwise equality (NaN == NaN).
void expect_bits_equal(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
  ASSERT_EQ(a.size(), b.size());
  if (!a.empty()) {
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)), 0);
  }
}

}  // namespace

TEST(PlyWriter, RoundTripsExactlyInAllEncodings) {
  const hprt::test::TempDir d("hprt_ply_writer");
  for (bool normals : {false, true}) {
    const TriangleMesh m = grid(normals);
    for (PlyFormat f :
         {PlyFormat::kAscii, PlyFormat::kBinaryLittleEndian, PlyFormat::kBinaryBigEndian}) {
      const std::string p = d.path(std::string("g").append(std::to_string(int(f))).append(".ply"));
      hprt::write_ply(m, p, f);
      const TriangleMesh r = hprt::load_mesh(p);
      expect_bits_equal(r.positions.to_vector(), m.positions.to_vector());
      expect_bits_equal(r.normals, m.normals);
      EXPECT_EQ(r.triangles, m.triangles);
    }
  }
}

TEST(PlyWriter, HeaderAndBinaryLayout) {
  const hprt::test::TempDir d("hprt_ply_writer");
  const TriangleMesh m = grid(true);
  const std::string p = d.path("be.ply");
  hprt::write_ply(m, p, PlyFormat::kBinaryBigEndian);
  const std::string bytes = slurp(p);
  const std::string header =
      "ply\nformat binary_big_endian 1.0\ncomment written by hprt\nelement vertex 49\n"
      "property float x\nproperty float y\nproperty float z\nproperty float nx\n"
      "property float ny\nproperty float nz\nelement face 72\n"
      "property list uchar int vertex_indices\nend_header\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  EXPECT_EQ(bytes.size(), header.size() + 49 * 24 + 72 * 13);
  // Vertex 1's x is 0.1f, stored most significant byte first.
  uint32_t u;
  const float x = m.positions[1].x;
  std::memcpy(&u, &x, 4);
  const unsigned char* v1 =
      reinterpret_cast<const unsigned char*>(bytes.data() + header.size() + 24);
  EXPECT_EQ(v1[0], u >> 24);
  EXPECT_EQ(v1[3], u & 0xff);
  EXPECT_EQ(bytes[header.size() + 49 * 24], 3);  // first face count
}

TEST(PlyWriter, NoNormalPropertiesWithoutNormals) {
  const hprt::test::TempDir d("hprt_ply_writer");
  const std::string p = d.path("a.ply");
  hprt::write_ply(grid(false), p, PlyFormat::kAscii);
  const std::string text = slurp(p);
  EXPECT_EQ(text.rfind("ply\nformat ascii 1.0\n", 0), 0u);
  EXPECT_EQ(text.find("nx"), std::string::npos);
  EXPECT_NE(text.find("\n3 0 1 8\n"), std::string::npos);
}

TEST(PlyWriter, UnwritableDirectoryIsErrorAndLeavesNothing) {
  EXPECT_THROW(hprt::write_ply(grid(false), "/nonexistent_hprt_dir/x.ply"), hprt::InputError);
  const hprt::test::TempDir d("hprt_ply_writer");
  hprt::write_ply(grid(false), d.path("only.ply"));
  for (const auto& e : fs::directory_iterator(d.dir)) EXPECT_EQ(e.path().filename(), "only.ply");
}
