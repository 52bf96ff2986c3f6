// PLY reader: assimp's sample files, the three encodings of one mesh with
// unusual types and extra data, tristrips, non-finite data, hostile headers.
#include "io/mesh/ply_reader.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "core/error.h"
#include "io/mesh/mesh_reader.h"
#include "tests/support/io_test_files.h"

namespace fs = std::filesystem;
using hprt::InputError;
using hprt::TriangleMesh;
using hprt::Vec3f;
using hprt::Vec3u;

namespace {

// Expects read_ply to throw InputError whose message starts with the path and
// contains `part`.
void expect_ply_error(const std::string& bytes, const std::string& part) {
  const std::string path = "t.ply";
  try {
    hprt::read_ply(path, bytes);
    ADD_FAILURE() << "no error; wanted one containing '" << part << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

// Binary writer for hand-made records.
struct Bytes {
  std::string s;
  bool big = false;
  template <typename T>
  Bytes& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof v);
    if (big != (std::endian::native == std::endian::big))
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    s.append(b, sizeof b);
    return *this;
  }
};

// The mesh every hand-written file below encodes: a quad (two triangles by
// fan) and a triangle over 5 vertices, with normals.
TriangleMesh expected_mesh() {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, -2.25f}, {3, 1e-3f, 7}};
  m.normals = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {0, 0, -1}, {0.6f, 0.8f, 0}};
  m.triangles = {Vec3u{{0, 1, 2}}, Vec3u{{0, 2, 3}}, Vec3u{{1, 4, 2}}};
  return m;
}

// Header with extra vertex properties, double coordinates, an extra element
// with a list, a face element with ushort indices under `vertex_index` and a
// trailing scalar.
std::string odd_header(const char* format) {
  return std::string("ply\r\nformat ") + format +
         " 1.0\r\ncomment odd layout\r\nobj_info test\r\n"
         "element vertex 5\r\nproperty uchar red\r\nproperty double x\r\nproperty float "
         "confidence\r\n"
         "property double y\r\nproperty double z\r\nproperty float nx\r\nproperty float ny\r\n"
         "property float nz\r\nproperty int8 flags\r\n"
         "element material 2\r\nproperty list uint8 float32 rgb\r\nproperty uint16 id\r\n"
         "element face 2\r\nproperty list uint8 uint16 vertex_index\r\nproperty uint32 tag\r\n"
         "end_header\r\n";
}

std::string odd_ascii() {
  const TriangleMesh m = expected_mesh();
  std::string s = odd_header("ascii");
  char line[256];
  for (int i = 0; i < 5; ++i) {
    const Vec3f& p = m.positions[i];
    const Vec3f& n = m.normals[i];
    std::snprintf(line, sizeof line, "%d %.9g 0.5 %.9g %.9g %.9g %.9g %.9g -%d\n", 200 + i, p.x,
                  p.y, p.z, n.x, n.y, n.z, i);
    s += line;
  }
  s += "3 0.1 0.2 0.3 7\n0 8\n4 0 1 2 3 99\n3 1 4 2 100\n";
  return s;
}

std::string odd_binary(bool big) {
  const TriangleMesh m = expected_mesh();
  Bytes b;
  b.big = big;
  b.s = odd_header(big ? "binary_big_endian" : "binary_little_endian");
  for (int i = 0; i < 5; ++i) {
    const Vec3f& p = m.positions[i];
    const Vec3f& n = m.normals[i];
    b.put<uint8_t>(uint8_t(200 + i)).put<double>(p.x).put<float>(0.5f).put<double>(p.y);
    b.put<double>(p.z).put<float>(n.x).put<float>(n.y).put<float>(n.z).put<int8_t>(int8_t(-i));
  }
  b.put<uint8_t>(3).put<float>(0.1f).put<float>(0.2f).put<float>(0.3f).put<uint16_t>(7);
  b.put<uint8_t>(0).put<uint16_t>(8);
  b.put<uint8_t>(4).put<uint16_t>(0).put<uint16_t>(1).put<uint16_t>(2).put<uint16_t>(3);
  b.put<uint32_t>(99);
  b.put<uint8_t>(3).put<uint16_t>(1).put<uint16_t>(4).put<uint16_t>(2).put<uint32_t>(100);
  return b.s;
}

void expect_same_ply_mesh(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (size_t i = 0; i < a.positions.size(); ++i) EXPECT_EQ(a.positions[i], b.positions[i]) << i;
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.triangles, b.triangles);
}

}  // namespace

TEST(PlyReader, AssimpCubeAsciiQuadsMatchBinaryTriangles) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "PLY/cube.ply");
  // cube.ply: 8 vertices, 6 quads (header "element face 6", each row "4 a b c d")
  // -> 12 fan triangles; cube_binary.ply stores those same 12 triangles.
  const TriangleMesh ascii = hprt::load_mesh(hprt::test::kAssimpModels + "PLY/cube.ply");
  const TriangleMesh binary = hprt::load_mesh(hprt::test::kAssimpModels + "PLY/cube_binary.ply");
  EXPECT_EQ(ascii.vertex_count(), 8u);
  EXPECT_EQ(ascii.triangle_count(), 12u);
  EXPECT_EQ(ascii.triangles[0], (Vec3u{{0, 1, 2}}));  // fan of "4 0 1 2 3"
  EXPECT_EQ(ascii.triangles[1], (Vec3u{{0, 2, 3}}));
  expect_same_ply_mesh(ascii, binary);
  EXPECT_EQ(ascii.name, hprt::test::kAssimpModels + "PLY/cube.ply");
}

TEST(PlyReader, AssimpWusonSkipsTexcoordsKeepsNormals) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "PLY/Wuson.ply");
  // Header: element vertex 11184 (x y z nx ny nz s t), element face 3732, and
  // every face row starts with 3. It also has a bare "Created by ..." line.
  const TriangleMesh m = hprt::load_mesh(hprt::test::kAssimpModels + "PLY/Wuson.ply");
  EXPECT_EQ(m.vertex_count(), 11184u);
  EXPECT_EQ(m.triangle_count(), 3732u);
  ASSERT_EQ(m.normals.size(), 11184u);
  // First row: 0.163313 0.540615 -0.268688 0.241919 -0.961129 0.133063 ...
  EXPECT_EQ(m.positions[0], Vec3f(0.163313f, 0.540615f, -0.268688f));
  EXPECT_EQ(m.normals[0], Vec3f(0.241919f, -0.961129f, 0.133063f));
}

TEST(PlyReader, AssimpFloatColorSkipsColors) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "PLY/float-color.ply");
  // 3 vertices with float red/green/blue/alpha and one face "3 0 1 2".
  const TriangleMesh m = hprt::load_mesh(hprt::test::kAssimpModels + "PLY/float-color.ply");
  ASSERT_EQ(m.vertex_count(), 3u);
  EXPECT_EQ(m.positions[2], Vec3f(200, 200, 0));
  ASSERT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.triangles[0], (Vec3u{{0, 1, 2}}));
  EXPECT_TRUE(m.normals.empty());
}

TEST(PlyReader, AssimpFilesWithoutFacesAreErrors) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "PLY/points.ply");
  for (const char* f :
       {"PLY/points.ply", "PLY/issue623.ply", "PLY/pond.0.ply", "invalid/empty.ply"})
    EXPECT_THROW(hprt::load_mesh(hprt::test::kAssimpModels + f), InputError) << f;
}

TEST(PlyReader, OddLayoutSameMeshInAllThreeEncodings) {
  const TriangleMesh want = expected_mesh();
  expect_same_ply_mesh(hprt::read_ply("a.ply", odd_ascii()), want);
  expect_same_ply_mesh(hprt::read_ply("le.ply", odd_binary(false)), want);
  expect_same_ply_mesh(hprt::read_ply("be.ply", odd_binary(true)), want);
}

TEST(PlyReader, FanTriangulatesPolygonsInOrder) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 2 0\n1 2 0\n"
      "5 0 1 2 3 4\n3 3 2 5\n";
  const TriangleMesh m = hprt::read_ply("p.ply", s);
  // Pentagon -> 3 triangles, then the triangle.
  const std::vector<Vec3u> want = {Vec3u{{0, 1, 2}}, Vec3u{{0, 2, 3}}, Vec3u{{0, 3, 4}},
                                   Vec3u{{3, 2, 5}}};
  EXPECT_EQ(m.triangles, want);
}

TEST(PlyReader, TristripsRestartFlipAndSkipJoints) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
      "property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n"
      "0 0 0\n0 1 0\n1 0 0\n1 1 0\n2 0 0\n2 1 0\n3 0 0\n3 1 0\n"
      "12 0 1 2 3 4 -1 4 5 6 6 7 7\n";
  const TriangleMesh m = hprt::read_ply("s.ply", s);
  // Run 0 1 2 3 4: (0,1,2), odd (1,2,3) -> (2,1,3), (2,3,4).
  // Run 4 5 6 6 7 7: (4,5,6), odd (5,6,6) joint skipped, (6,6,7) skipped,
  // odd (6,7,7) skipped.
  const std::vector<Vec3u> want = {Vec3u{{0, 1, 2}}, Vec3u{{2, 1, 3}}, Vec3u{{2, 3, 4}},
                                   Vec3u{{4, 5, 6}}};
  EXPECT_EQ(m.triangles, want);
}

TEST(PlyReader, TristripsKeepParityAcrossJoints) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
      "property float z\nelement tristrips 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n0 1 0\n1 0 0\n1 1 0\n2 0 0\n2 1 0\n"
      "6 0 1 1 2 3 4\n";
  // j=0 (0,1,1) skip, j=1 (1,1,2) skip, j=2 (1,2,3) even, j=3 (2,3,4) odd -> (3,2,4).
  const std::vector<Vec3u> want = {Vec3u{{1, 2, 3}}, Vec3u{{3, 2, 4}}};
  EXPECT_EQ(hprt::read_ply("s.ply", s).triangles, want);
}

TEST(PlyReader, NonFiniteCoordinatesLoadAsInvalidTriangles) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property double z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 nan\n+1e-2 inf -inf\n0 1 1e400\n3 0 1 2\n3 0 3 4\n";
  const TriangleMesh m = hprt::read_ply("n.ply", s);
  ASSERT_EQ(m.triangle_count(), 2u);
  EXPECT_TRUE(std::isnan(m.positions[2].z));
  EXPECT_EQ(m.positions[3].x, 0.01f);
  EXPECT_EQ(m.positions[3].y, std::numeric_limits<float>::infinity());
  EXPECT_EQ(m.positions[4].z, std::numeric_limits<float>::infinity());
  EXPECT_FALSE(m.triangle_valid(0));
  EXPECT_FALSE(m.triangle_valid(1));
}

TEST(PlyReader, HugeVertexCountFailsBeforeAllocating) {
  // 4e9 float vertices claim 48 GB; the file holds a few bytes.
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  s += std::string(200 - s.size(), '\0');
  expect_ply_error(s, "header declares 4000000000 vertex records");
  std::string a =
      "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
      "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 "
      "0\n";
  expect_ply_error(a, "header declares 4000000000 vertex records");
}

TEST(PlyReader, HugeFaceCountFailsBeforeAllocating) {
  Bytes b;
  b.s =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 18446744073709551615\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) b.put<float>(1.0f);
  expect_ply_error(b.s, "header declares 18446744073709551615 face records");
}

TEST(PlyReader, NegativeListCountIsError) {
  Bytes b;
  b.s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list int int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) b.put<float>(1.0f);
  b.put<int32_t>(-5).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
  expect_ply_error(b.s, "face 0: negative list count -5");
  std::string a =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n"
      "0 0 0\n0 0 0\n0 0 0\n-3 0 1 2\n";
  expect_ply_error(a, "negative list count -3");
}

TEST(PlyReader, FaceOfFewerThanThreeVerticesIsError) {
  // As in OBJ files: every path (ASCII, the uchar/int fast path, other list
  // types) names the face.
  const std::string head =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\n";
  for (int n = 0; n < 3; ++n) {
    // Built by appending: g++ 12 reports a false -Wrestrict on some chains of +.
    std::string want = "face 1: face with ";
    want.append(std::to_string(n)).append(" vertices");
    std::string a = "ply\nformat ascii 1.0\n";
    a.append(head).append("property list uchar int vertex_indices\nend_header\n");
    a.append("0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").append(std::to_string(n));
    for (int k = 0; k < n; ++k) a.append(" ").append(std::to_string(k));
    expect_ply_error(a.append("\n"), want + " (at least 3 needed)");
    for (const std::string list : {"uchar int", "ushort uint"}) {
      Bytes b;
      b.s = "ply\nformat binary_little_endian 1.0\n";
      b.s.append(head).append("property list ").append(list);
      b.s.append(" vertex_indices\nend_header\n");
      for (int i = 0; i < 9; ++i) b.put<float>(i == 3 || i == 7 ? 1.0f : 0.0f);
      const auto count = [&](int c) {
        if (list == "uchar int")  // the fast path
          b.put<uint8_t>(uint8_t(c));
        else
          b.put<uint16_t>(uint16_t(c));
      };
      count(3);
      b.put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
      count(n);
      for (int k = 0; k < n; ++k) b.put<int32_t>(k);
      expect_ply_error(b.s, want);
    }
  }
}

TEST(PlyReader, AbsurdListCountIsError) {
  Bytes b;
  b.s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uint int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) b.put<float>(1.0f);
  b.put<uint32_t>(4000000000u).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
  expect_ply_error(b.s, "list count 4000000000 exceeds the remaining data");
}

TEST(PlyReader, ListCountInOtherElementIsChecked) {
  Bytes b;
  b.s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nproperty list ushort double junk\n"
      "element face 0\nproperty list uchar int vertex_indices\nend_header\n";
  b.put<float>(0).put<float>(0).put<float>(0).put<uint16_t>(60000);
  expect_ply_error(b.s, "vertex 0: list count 60000 exceeds the remaining data");
}

TEST(PlyReader, TruncatedBinaryIsError) {
  Bytes b;
  b.s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 2\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) b.put<float>(1.0f);
  b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
  b.put<uint8_t>(3).put<int32_t>(0);  // second face cut short
  expect_ply_error(b.s, "face 1: truncated data");
  // Cut inside the vertex data: the size check fires first.
  expect_ply_error(odd_binary(false).substr(0, odd_header("binary_little_endian").size() + 50),
                   "vertex records");
}

TEST(PlyReader, TruncatedAsciiIsError) {
  std::string a = odd_ascii();
  expect_ply_error(a.substr(0, a.size() - 4), "face 1: truncated data");  // tag 100 cut off
  expect_ply_error(a.substr(0, a.size() - 8), "face 1: list count 3 exceeds the remaining data");
}

TEST(PlyReader, UnknownPropertyTypeIsError) {
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n0\n",
                   "unknown property type 'float128'");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int24 vertex_indices\n"
      "end_header\n0\n",
      "unknown property type 'int24'");
}

TEST(PlyReader, UnknownFormatIsError) {
  expect_ply_error("ply\nformat binary_middle_endian 1.0\nelement vertex 0\nend_header\n",
                   "unknown format 'binary_middle_endian'");
  expect_ply_error("ply\nelement vertex 0\nend_header\n", "no format line");
}

TEST(PlyReader, IndexOutOfRangeNamesFaceAndVertex) {
  std::string a =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 900 1\n";
  expect_ply_error(a, "face 1: references vertex 900 of 3");
  Bytes b;
  b.s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) b.put<float>(1.0f);
  b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(-7).put<int32_t>(2);
  expect_ply_error(b.s, "face 0: references vertex -7 of 3");
}

TEST(PlyReader, NotAPlyFileIsError) {
  expect_ply_error("", "not a PLY file");
  expect_ply_error("solid cube\nfacet normal 0 0 1\n", "not a PLY file");
  expect_ply_error(std::string("ply\n\x01\x02\x03\xff", 8), "binary data inside the header");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\n", "no end_header");
}

TEST(PlyReader, MissingCoordinatesOrVertexElementAreErrors) {
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0\n",
      "vertex element has no z property");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n"
      "end_header\n",
      "no vertex element");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty uchar flags\nend_header\n0 0 0\n1\n",
      "face 0: element has no vertex_indices list property");
}

TEST(PlyReader, GarbageAsciiNumberIsError) {
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0x1 0\n",
      "vertex 0: '0x1' is not a number");
  expect_ply_error(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n0 0 0\n0 0 0\n3 0 1.5 2\n",
      "face 0: '1.5' is not an integer");
}
