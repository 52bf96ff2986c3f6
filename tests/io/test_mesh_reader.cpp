// load_mesh: dispatch by extension, .gz transparency for both formats,
// corrupt or truncated gzip, missing, empty and unknown files.
#include "io/mesh/mesh_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "io/files/file_bytes.h"
#include "tests/support/cli_test_support.h"
#include "tests/support/io_test_files.h"

namespace fs = std::filesystem;
using hprt::InputError;
using hprt::TriangleMesh;

namespace {

using hprt::test::slurp;

struct GzTempDir : hprt::test::TempDir {
  GzTempDir() : TempDir("hprt_mesh_reader") {}
  std::string write_gz(const std::string& name, const std::string& bytes) const {
    gzFile f = gzopen(path(name).c_str(), "wb");
    EXPECT_NE(f, nullptr);
    EXPECT_EQ(gzwrite(f, bytes.data(), static_cast<unsigned>(bytes.size())), int(bytes.size()));
    gzclose(f);
    return path(name);
  }
};

// Expects load_mesh(path) to throw InputError "path: ...part...".
void expect_load_error(const std::string& path, const std::string& part) {
  try {
    hprt::load_mesh(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

const std::string kPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
const std::string kObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

void expect_same_mesh(const TriangleMesh& a, const TriangleMesh& b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.material, b.material);
}

}  // namespace

TEST(MeshReader, DispatchesByExtensionCaseInsensitive) {
  GzTempDir d;
  const TriangleMesh ply = hprt::load_mesh(d.write("a.PLY", kPly));
  const TriangleMesh obj = hprt::load_mesh(d.write("b.Obj", kObj));
  EXPECT_EQ(ply.triangle_count(), 2u);
  expect_same_mesh(ply, obj);
  EXPECT_EQ(ply.name, d.path("a.PLY"));
  EXPECT_EQ(obj.name, d.path("b.Obj"));
}

TEST(MeshReader, GzipPlyEqualsPlain) {
  GzTempDir d;
  expect_same_mesh(hprt::load_mesh(d.write_gz("a.ply.gz", kPly)),
                   hprt::load_mesh(d.write("a.ply", kPly)));
  EXPECT_EQ(hprt::load_mesh(d.path("a.ply.gz")).name, d.path("a.ply.gz"));
}

TEST(MeshReader, GzipObjEqualsPlain) {
  GzTempDir d;
  expect_same_mesh(hprt::load_mesh(d.write_gz("a.OBJ.GZ", kObj)),
                   hprt::load_mesh(d.write("a.obj", kObj)));
}

TEST(MeshReader, ConcatenatedGzipMembersAreOneFile) {
  GzTempDir d;
  const std::string a = slurp(d.write_gz("a.gz", kPly.substr(0, 100)));
  const std::string b = slurp(d.write_gz("b.gz", kPly.substr(100)));
  expect_same_mesh(hprt::load_mesh(d.write("ab.ply.gz", a + b)),
                   hprt::load_mesh(d.write("p.ply", kPly)));
}

TEST(MeshReader, TruncatedGzipIsError) {
  GzTempDir d;
  const std::string gz = slurp(d.write_gz("full.ply.gz", kPly));
  expect_load_error(d.write("cut.ply.gz", gz.substr(0, gz.size() / 2)), "truncated gzip data");
  expect_load_error(d.write("cut2.ply.gz", gz.substr(0, gz.size() - 4)), "gzip data");
}

TEST(MeshReader, CorruptGzipIsError) {
  GzTempDir d;
  std::string gz = slurp(d.write_gz("full.obj.gz", kObj));
  for (size_t i = 12; i < gz.size() - 8; ++i) gz[i] = static_cast<char>(gz[i] ^ 0x5a);
  expect_load_error(d.write("bad.obj.gz", gz), "gzip data");
  expect_load_error(d.write("plain.obj.gz", kObj), "not a gzip file");
  expect_load_error(d.write("trail.obj.gz", slurp(d.path("full.obj.gz")) + "junk"),
                    "trailing garbage");
}

TEST(MeshReader, DecompressionLimitIsEnforced) {
  const std::string big(1 << 20, 'v');
  GzTempDir d;
  const std::string gz = slurp(d.write_gz("bomb.gz", big));
  EXPECT_THROW(hprt::gunzip_bytes("bomb.gz", gz, 4096), InputError);
  EXPECT_EQ(hprt::gunzip_bytes("bomb.gz", gz, big.size()).size(), big.size());
  EXPECT_THROW(hprt::read_file_bytes(d.path("bomb.gz"), 1000), InputError);
}

TEST(MeshReader, MissingFileIsError) {
  const std::string p = "/nonexistent_hprt_dir/mesh.ply";
  try {
    hprt::load_mesh(p);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), p + ": cannot open: No such file or directory");
  }
}

TEST(MeshReader, EmptyFileIsError) {
  GzTempDir d;
  expect_load_error(d.write("e.ply", ""), "empty file");
  expect_load_error(d.write("e.obj", ""), "empty file");
  expect_load_error(d.write_gz("e.obj.gz", ""), "empty file");
}

TEST(MeshReader, UnknownExtensionIsError) {
  GzTempDir d;
  expect_load_error(d.write("a.stl", kPly), "unknown mesh format");
  expect_load_error(d.write("noext", kPly), "unknown mesh format");
  expect_load_error(d.write("a.gz", kPly), "unknown mesh format");
}

TEST(MeshReader, BinaryJunkNamedObjIsError) {
  GzTempDir d;
  std::string junk;
  for (int i = 0; i < 4096; ++i) junk += static_cast<char>((i * 131 + 7) & 0xff);
  expect_load_error(d.write("junk.obj", junk), "binary data");
  expect_load_error(d.write("junk.ply", junk), "not a PLY file");
}

TEST(MeshReader, MeshWithoutTrianglesIsError) {
  GzTempDir d;
  expect_load_error(d.write("points.obj", "v 0 0 0\nv 1 1 1\n"), "no triangles");
}

TEST(MeshReader, DirectoryIsError) {
  GzTempDir d;
  fs::create_directories(d.dir / "dir.ply");
  expect_load_error(d.path("dir.ply"), "cannot open");
}
