// OBJ reader: assimp's sample files, fan order across objects and groups,
// materials and normals policy, and malformed lines named by file and line.
#include "io/mesh/obj_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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

void expect_obj_error(const std::string& text, const std::string& part) {
  const std::string path = "m.obj";
  try {
    hprt::read_obj(path, text);
    ADD_FAILURE() << "no error; wanted one containing '" << part << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

}  // namespace

TEST(ObjReader, AssimpBoxQuads) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "OBJ/box.obj");
  // 8 `v` lines, 6 `f` lines of 4 vertices -> 12 triangles.
  const TriangleMesh m = hprt::load_mesh(hprt::test::kAssimpModels + "OBJ/box.obj");
  EXPECT_EQ(m.vertex_count(), 8u);
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_EQ(m.positions[0], Vec3f(-0.5f, -0.5f, 0.5f));
}

TEST(ObjReader, AssimpSpiderGroupsMaterialsNormals) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "OBJ/spider.obj");
  // 762 `v`, 747 `vn`, 1368 triangular `f` lines in 19 groups. Triangles per
  // material (awk over usemtl/f): BeinTex 952, Skin 260, HLeibTex 80, ...;
  // BeinTex has Kd 0.8 0.8 0.8, Ks 0, Ns 0.
  const TriangleMesh m = hprt::load_mesh(hprt::test::kAssimpModels + "OBJ/spider.obj");
  EXPECT_EQ(m.vertex_count(), 762u);
  EXPECT_EQ(m.triangle_count(), 1368u);
  EXPECT_EQ(m.normals.size(), 762u);
  EXPECT_EQ(m.material.diffuse, Vec3f(0.8f, 0.8f, 0.8f));
  EXPECT_EQ(m.material.specular, Vec3f(0, 0, 0));
  EXPECT_EQ(m.material.shininess, 0.0f);
}

TEST(ObjReader, AssimpWuson) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "OBJ/WusonOBJ.obj");
  // 2117 `v`, 2076 `vn`, 3732 triangular `f` lines.
  const TriangleMesh m = hprt::load_mesh(hprt::test::kAssimpModels + "OBJ/WusonOBJ.obj");
  EXPECT_EQ(m.vertex_count(), 2117u);
  EXPECT_EQ(m.triangle_count(), 3732u);
  EXPECT_EQ(m.normals.size(), 2117u);
}

TEST(ObjReader, AssimpConcavePolygonFan) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "OBJ/concave_polygon.obj");
  // One `f` line with 66 vertex references -> 64 fan triangles; material
  // "test" has Kd 0.141176 0.184314 0.411765 and Ns 400.
  const TriangleMesh m = hprt::load_mesh(hprt::test::kAssimpModels + "OBJ/concave_polygon.obj");
  EXPECT_EQ(m.vertex_count(), 64u);
  ASSERT_EQ(m.triangle_count(), 64u);
  for (size_t i = 0; i < m.triangle_count(); ++i) {
    EXPECT_EQ(m.triangles[i][0], m.triangles[0][0]);
    if (i > 0) {
      EXPECT_EQ(m.triangles[i][1], m.triangles[i - 1][2]);
    }
  }
  EXPECT_EQ(m.material.diffuse, Vec3f(0.141176f, 0.184314f, 0.411765f));
  EXPECT_EQ(m.material.shininess, 400.0f);
}

TEST(ObjReader, AssimpInvalidFilesAreErrors) {
  HPRT_SKIP_IF_MISSING(hprt::test::kAssimpModels + "invalid/malformed.obj");
  // malformed.obj: index 0 and 12 of 8; malformed2.obj: a bare "f" line.
  EXPECT_THROW(hprt::load_mesh(hprt::test::kAssimpModels + "invalid/malformed.obj"), InputError);
  EXPECT_THROW(hprt::load_mesh(hprt::test::kAssimpModels + "invalid/malformed2.obj"), InputError);
  EXPECT_THROW(hprt::load_mesh(hprt::test::kAssimpModels + "invalid/empty.obj"), InputError);
  // "3.1+e2" is not a number (line 11); UTF-16 text is binary to us.
  EXPECT_THROW(hprt::load_mesh(hprt::test::kAssimpModels + "OBJ/number_formats.obj"), InputError);
  EXPECT_THROW(hprt::load_mesh(hprt::test::kAssimpModels + "OBJ/box_UTF16BE.obj"), InputError);
}

TEST(ObjReader, ObjectsAndGroupsMergeInFileOrder) {
  const std::string text =
      "o first\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
      "g second\nv 2 0 0\nf 2 5 3\ng\no third\r\nf -5 -1 -3\r\n"
      "s 1\nf 1/1 2/2 3/3\nvt 0 0\nvt 1 0\nvt 1 1\n";
  const TriangleMesh m = hprt::read_obj("m.obj", text);
  const std::vector<Vec3u> want = {Vec3u{{0, 1, 2}}, Vec3u{{0, 2, 3}}, Vec3u{{1, 4, 2}},
                                   Vec3u{{0, 4, 2}}, Vec3u{{0, 1, 2}}};
  EXPECT_EQ(m.triangles, want);
  EXPECT_TRUE(m.normals.empty());
  EXPECT_EQ(m.name, "m.obj");
}

TEST(ObjReader, LargePolygonBeyondTinyobjShapeLimit) {
  std::string text;
  const int n = 300;
  for (int i = 0; i < n; ++i)
    text.append("v ")
        .append(std::to_string(std::cos(i * 0.02)))
        .append(" ")
        .append(std::to_string(std::sin(i * 0.02)))
        .append(" 0\n");
  text += "f";
  for (int i = 1; i <= n; ++i) text.append(" ").append(std::to_string(i));
  text += "\n";
  const TriangleMesh m = hprt::read_obj("big.obj", text);
  ASSERT_EQ(m.triangle_count(), size_t(n - 2));
  EXPECT_EQ(m.triangles.back(), (Vec3u{{0, uint32_t(n - 2), uint32_t(n - 1)}}));
}

TEST(ObjReader, ConsistentNormalsKeptMixedOnesAveraged) {
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
      "vn 0 0 2\nvn 1 0 0\n"
      "f 1//1 2//1 3//1\nf 1//2 3//2 4//2\n";
  const TriangleMesh m = hprt::read_obj("n.obj", text);
  ASSERT_EQ(m.normals.size(), 4u);
  EXPECT_EQ(m.normals[1], Vec3f(0, 0, 2));  // one vn: kept as written
  EXPECT_EQ(m.normals[3], Vec3f(1, 0, 0));
  const float h = 1.0f / std::sqrt(2.0f);  // vertices 0 and 2: two vn, unit sum
  EXPECT_NEAR(m.normals[0].x, h, 1e-6f);
  EXPECT_NEAR(m.normals[0].z, h, 1e-6f);
  EXPECT_EQ(m.normals[0], m.normals[2]);
}

TEST(ObjReader, NormalsDroppedWhenSomeFaceVerticesLackThem) {
  const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3\n";
  EXPECT_TRUE(hprt::read_obj("n.obj", text).normals.empty());
}

TEST(ObjReader, MostUsedMaterialWins) {
  hprt::test::TempDir dir("hprt_obj_mtl");
  dir.write("m.mtl",
            "newmtl a\nKd 1 0 0\nKs 0.5 0.5 0.5\nNs 10\n"
            "newmtl b\nKd 0 1 0\nKs 0.25 0.25 0.25\nNs 77\n");
  const std::string path = dir.write(
      "m.obj",
      "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "usemtl a\nf 1 2 3\nusemtl b\nf 1 2 3 4\nusemtl missing\nf 1 2 3\nf 1 2 3\nf 1 2 3\n");
  const TriangleMesh m = hprt::load_mesh(path);
  EXPECT_EQ(m.material.diffuse, Vec3f(0, 1, 0));  // b: 2 triangles, a: 1, unknown: no vote
  EXPECT_EQ(m.material.specular, Vec3f(0.25f, 0.25f, 0.25f));
  EXPECT_EQ(m.material.shininess, 77.0f);
}

TEST(ObjReader, MissingMtlFileGivesDefaultMaterial) {
  const TriangleMesh m = hprt::read_obj("/nonexistent/x.obj",
                                        "mtllib nope.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\n"
                                        "v 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(m.material, hprt::Material{});
}

TEST(ObjReader, NonFiniteVerticesAreData) {
  const TriangleMesh m =
      hprt::read_obj("n.obj", "v nan 0 0\nv 1 inf 0\nv 0 1 1e999\nv 0 0 0\nf 1 2 3\nf 2 3 4\n");
  ASSERT_EQ(m.triangle_count(), 2u);
  EXPECT_TRUE(std::isnan(m.positions[0].x));
  EXPECT_TRUE(std::isinf(m.positions[1].y));
  EXPECT_TRUE(std::isinf(m.positions[2].z));
  EXPECT_FALSE(m.triangle_valid(0));
  EXPECT_FALSE(m.triangle_valid(1));
}

TEST(ObjReader, GarbageFaceLineNamesLine) {
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 x\n", "line 5: bad face vertex 'x'");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3.5\n", "line 4: bad face vertex '3.5'");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "line 4: face with 2 vertices");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "line 4: bad face vertex");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4: face vertex '0' has index 0");
}

TEST(ObjReader, GarbageNumbersAndStatementsNameLine) {
  expect_obj_error("v 0 0 0\nv 1 zero 0\n", "line 2: 'zero' is not a number");
  expect_obj_error("v 0 0\n", "line 1: v needs 3 to 7 numbers, found 2");
  expect_obj_error("vn 0 0 1 1\n", "line 1: vn needs 3 numbers, found 4");
  expect_obj_error("v 0 0 0\nfoo bar\n", "line 2: unknown OBJ statement 'foo'");
}

TEST(ObjReader, IndexOutOfRangeNamesLine) {
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\nf 1 2 3\n",
                   "line 5: face references vertex 9 of 3");
  expect_obj_error("v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n",
                   "line 3: face references vertex -3 (relative) with only 2 defined before it");
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
                   "line 5: face references normal 2 of 1");
}

TEST(ObjReader, BinaryJunkIsError) {
  std::string junk = "v 0 0 0\n";
  for (int i = 0; i < 256; ++i) junk += static_cast<char>((i * 37 + 11) & 0xff);
  expect_obj_error(junk, "line 2: binary data");
}
