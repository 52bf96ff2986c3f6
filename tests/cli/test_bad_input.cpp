// Bad input through the real CLI: every case must end with one line
// "hprt: error: ..." naming the culprit, exit code 2, and no output file (or
// temporary) left behind. Also the inputs that must still work: non-finite
// vertices (dropped and counted, the rest renders) and empty scenes
// (background image, all rays miss). With HPRT_BAD_INPUT_LOG=FILE set, each
// case appends "case | command | exit code | message" to FILE (the closing
// note's list is made that way).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "io/image/image_io.h"
#include "io/rays/ray_file.h"
#include "tests/support/cli_test_support.h"

namespace fs = std::filesystem;

namespace hprt {
namespace {

using test::CliResult;
using test::slurp;

void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

const char* kPlyHead =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
const char* kTriangleData = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

// A binary little-endian PLY: 3 vertices, one face whose list count has
// type `count_type` and raw bytes `count_bytes`, followed by indices 0 1 2.
std::string binary_ply_with_count(const std::string& count_type, const std::string& count_bytes) {
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list " +
      count_type + " int vertex_indices\nend_header\n";
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  s.append(reinterpret_cast<const char*>(v), sizeof v);
  s += count_bytes;
  const int32_t idx[3] = {0, 1, 2};
  s.append(reinterpret_cast<const char*>(idx), sizeof idx);
  return s;
}

class BadInput : public test::CliTest {
 protected:
  BadInput() : CliTest("hprt_bad_input_") {}
  void SetUp() override {
    CliTest::SetUp();
    spit(dir_ / "good.ply", std::string(kPlyHead) + kTriangleData);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_ / "ro", fs::perms::owner_all, ec);
    CliTest::TearDown();
  }

  // Runs `hprt args` in dir_ (so relative names in args are inside it).
  // `prefix` is shell text run before hprt in the same shell (e.g. a ulimit).
  CliResult run(const std::string& args, const std::string& prefix = "") const {
    return test::run_hprt(args, dir_, dir_, prefix);
  }

  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(dir_))
      names.insert(fs::relative(e.path(), dir_).string());
    return names;
  }

  // The case must fail with exit code 2, one stderr line starting
  // "hprt: error: " that contains every string of `mentions`, nothing on
  // stdout, and no new file anywhere in the directory.
  void expect_rejected(const std::string& what, const std::string& args,
                       const std::vector<std::string>& mentions,
                       const std::string& prefix = "") const {
    const std::set<std::string> before = files();
    const CliResult r = run(args, prefix);
    log(what, args, r);
    EXPECT_EQ(r.code, 2) << what << ": " << r.err;
    EXPECT_EQ(r.err.rfind("hprt: error: ", 0), 0u) << what << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << ": " << r.err;
    for (const std::string& m : mentions)
      EXPECT_NE(r.err.find(m), std::string::npos) << what << ": '" << m << "' not in " << r.err;
    EXPECT_EQ(r.out, "") << what;
    EXPECT_EQ(files(), before) << what << ": output or temporary file left behind";
  }

  static void log(const std::string& what, const std::string& args, const CliResult& r) {
    const char* log_path = std::getenv("HPRT_BAD_INPUT_LOG");
    if (!log_path) return;
    std::string msg = r.err;
    while (!msg.empty() && msg.back() == '\n') msg.pop_back();
    for (char& c : msg)
      if (c == '\n') c = ' ';
    std::ofstream(log_path, std::ios::app)
        << "| " << what << " | `hprt " << args << "` | " << r.code << " | " << msg << " |\n";
  }
};

TEST_F(BadInput, PlyHeaderCountsLargerThanTheFile) {
  // 1e9 vertices declared, 26 bytes present: refused before any allocation.
  spit(dir_ / "a.ply",
       "ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" +
           std::string(kTriangleData));
  expect_rejected("PLY vertex count 1e9 in a 26-byte body", "build a.ply", {"a.ply", "1000000000"});
  spit(dir_ / "b.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
       "property float y\nproperty float z\nelement face 4000000000\nproperty list uchar int "
       "vertex_indices\nend_header\n" +
           std::string(36, '\0'));
  expect_rejected("binary PLY face count 4e9", "render b.ply -o out.png", {"b.ply", "face"});
  // The same under a 1 GiB address-space limit: a lying header that made the
  // reader allocate would fail with "out of memory" instead of the message.
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)  // they reserve huge shadows
  expect_rejected("PLY vertex count 1e9, under ulimit -v 1 GiB", "build a.ply",
                  {"a.ply", "1000000000"}, "ulimit -v 1048576 && ");
#endif
}

TEST_F(BadInput, IndicesOutOfRange) {
  spit(dir_ / "a.ply", std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expect_rejected("PLY face index 7 of 3 vertices", "build a.ply", {"a.ply", "face 0", "7"});
  spit(dir_ / "b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  expect_rejected("OBJ face index 9 of 3 vertices", "render b.obj -o out.png", {"b.obj", "line 4"});
  spit(dir_ / "c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9\n");
  expect_rejected("OBJ negative face index -9", "build c.obj", {"c.obj", "line 4"});
}

TEST_F(BadInput, UnknownFormatOrPropertyType) {
  spit(dir_ / "a.ply",
       "ply\nformat binary_middle_endian 1.0\nelement vertex 3\n"
       "property float x\nend_header\n");
  expect_rejected("PLY format binary_middle_endian", "build a.ply",
                  {"a.ply", "binary_middle_endian"});
  spit(dir_ / "b.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float128 x\nend_header\n");
  expect_rejected("PLY property type float128", "build b.ply", {"b.ply", "float128"});
  spit(dir_ / "c.stl", "solid x\nendsolid x\n");
  expect_rejected("unknown mesh extension .stl", "build c.stl", {"c.stl"});
  spit(dir_ / "d.ply", "not a ply file at all\n");
  expect_rejected("PLY without the 'ply' magic", "build d.ply", {"d.ply"});
}

TEST_F(BadInput, ListCountsNegativeOrAbsurd) {
  spit(dir_ / "a.ply", binary_ply_with_count("char", std::string(1, char(-3))));
  expect_rejected("binary PLY list count -3 (char)", "build a.ply", {"a.ply", "-3"});
  const uint32_t huge = 0xFFFFFFFFu;
  spit(dir_ / "b.ply",
       binary_ply_with_count("uint", std::string(reinterpret_cast<const char*>(&huge), 4)));
  expect_rejected("binary PLY list count 4294967295 (uint)", "build b.ply",
                  {"b.ply", "4294967295"});
  spit(dir_ / "c.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float "
       "y\nproperty float z\nelement face 1\nproperty list int int "
       "vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n");
  expect_rejected("ASCII PLY list count 2e9", "build c.ply", {"c.ply", "2000000000"});
}

TEST_F(BadInput, TruncatedBinaryAndGzip) {
  ASSERT_EQ(run("generate sphere --tris 2000 -o s.ply").code, 0);
  const std::string whole = slurp(dir_ / "s.ply");
  spit(dir_ / "trunc.ply", whole.substr(0, whole.size() / 2));
  expect_rejected("binary PLY cut in half", "build trunc.ply", {"trunc.ply", "truncated"});
  ASSERT_EQ(std::system(("gzip -c '" + path("s.ply") + "' > '" + path("s.ply.gz") + "'").c_str()),
            0);
  const std::string gz = slurp(dir_ / "s.ply.gz");
  spit(dir_ / "trunc.ply.gz", gz.substr(0, gz.size() / 2));
  expect_rejected("gzip PLY cut in half", "render trunc.ply.gz -o out.png",
                  {"trunc.ply.gz", "truncated"});
  std::string corrupt = gz;
  for (size_t i = 20; i < corrupt.size() - 8; i += 7) corrupt[i] = char(corrupt[i] ^ 0x5a);
  spit(dir_ / "corrupt.ply.gz", corrupt);
  expect_rejected("gzip PLY with flipped bytes", "build corrupt.ply.gz", {"corrupt.ply.gz"});
}

TEST_F(BadInput, FifosDevicesBombsAndLyingImages) {
  // Inputs that are not regular files are refused, never waited on (a FIFO
  // blocked open() for ever) or read until memory runs out (/dev/zero).
  ASSERT_EQ(::mkfifo(path("f.ply").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(path("f.png").c_str(), 0600), 0);
  expect_rejected("a FIFO as the mesh", "build f.ply", {"f.ply", "not a regular file"},
                  "timeout 20 ");
  ASSERT_EQ(run("render good.ply --width 16 -o a.png").code, 0);
  expect_rejected("a FIFO as an image", "validate image a.png f.png",
                  {"f.png", "not a regular file"}, "timeout 20 ");
  spit(
      dir_ / "dev.obj",
      "mtllib ../../../../../../../../../dev/zero\nusemtl x\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_rejected("an OBJ whose mtllib is /dev/zero", "build dev.obj",
                  {"dev/zero", "not a regular file"}, "timeout 20 ");
  spit(dir_ / "neg.mtl", "newmtl x\nKd -1 0.5 0.5\n");
  spit(dir_ / "neg.obj", "mtllib neg.mtl\nusemtl x\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_rejected("an .mtl with a negative Kd", "build neg.obj", {"neg.obj", "material 'x'"});
  // 200 MiB of zeros in a .gz of about 200 KB: stopped at 100 times its size
  // (64 MiB at least), well under a 1 GiB address-space limit.
  ASSERT_EQ(std::system(
                ("head -c 209715200 /dev/zero | gzip -1 > '" + path("bomb.ply.gz") + "'").c_str()),
            0);
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)  // they reserve huge shadows
  expect_rejected("a gzip bomb", "build bomb.ply.gz", {"bomb.ply.gz", "decompression bomb"},
                  "ulimit -v 1048576 && ");
#else
  expect_rejected("a gzip bomb", "build bomb.ply.gz", {"bomb.ply.gz", "decompression bomb"});
#endif
  // A PNG header claiming 30000 x 30000 pixels with no pixel data: refused at
  // its first missing row, not after allocating 10 GB.
  const auto chunk = [](const std::string& type, const std::string& data) {
    std::string c;
    const uint32_t n = uint32_t(data.size());
    for (int k = 3; k >= 0; --k) c += char((n >> (8 * k)) & 0xff);
    c += type + data;
    const uint32_t crc = uint32_t(::crc32(::crc32(0, nullptr, 0),
                                          reinterpret_cast<const Bytef*>((type + data).data()),
                                          uInt(type.size() + data.size())));
    for (int k = 3; k >= 0; --k) c += char((crc >> (8 * k)) & 0xff);
    return c;
  };
  // The IDAT chunk holds a few compressed zero bytes, so that the reader
  // gets past the header (without one it fails at once).
  std::string idat(64, '\0');
  uLongf idat_size = uLongf(idat.size());
  const std::string zeros(100, '\0');
  ASSERT_EQ(::compress(reinterpret_cast<Bytef*>(idat.data()), &idat_size,
                       reinterpret_cast<const Bytef*>(zeros.data()), uLong(zeros.size())),
            Z_OK);
  idat.resize(idat_size);
  const auto png = [&](const std::string& ihdr) {
    return "\x89PNG\r\n\x1a\n" + chunk("IHDR", ihdr) + chunk("IDAT", idat) + chunk("IEND", "");
  };
  const std::string ihdr("\x00\x00\x75\x30\x00\x00\x75\x30\x08\x02\x00\x00\x00", 13);
  spit(dir_ / "huge.png", png(ihdr));
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  expect_rejected("a PNG claiming 30000x30000 pixels", "validate image a.png huge.png",
                  {"huge.png", "more than hprt renders"}, "ulimit -v 3145728 && ");
#endif
  // 16000 x 16000, fewer pixels than that cap: read a strip at a time, the
  // file fails at its first missing row; interlaced, OIIO would allocate the
  // whole image on the first row, so the header is refused first (no 100
  // bytes of deflate data can hold it).
  std::string big = ihdr;
  big[2] = big[6] = '\x3e';
  big[3] = big[7] = '\x80';
  spit(dir_ / "big.png", png(big));
  expect_rejected("a PNG claiming 16000x16000 pixels", "validate image a.png big.png",
                  {"big.png", "PNG header claims 16000x16000 pixels of 24 bits",
                   "bytes of image data can hold"});
  big[12] = '\x01';
  spit(dir_ / "laced.png", png(big));
  expect_rejected("an interlaced PNG claiming 16000x16000 pixels", "validate image a.png laced.png",
                  {"laced.png", "PNG header claims 16000x16000 pixels of 24 bits",
                   "bytes of image data can hold"});
  // Only IDAT data counts: 40 KB of text padding do not make room for
  // 16384 x 16384 RGBA pixels of 16 bits (2 GiB decoded).
  std::string deep = big;
  deep[2] = deep[6] = '\x40';
  deep[3] = deep[7] = '\x00';
  deep[8] = '\x10', deep[9] = '\x06';
  const std::string padded =
      "\x89PNG\r\n\x1a\n" + chunk("IHDR", deep) +
      chunk("tEXt", "Comment" + std::string(1, '\0') + std::string(40000, 'x')) +
      chunk("IDAT", idat) + chunk("IEND", "");
  spit(dir_ / "padded.png", padded);
  expect_rejected("an interlaced PNG padded with text", "validate image a.png padded.png",
                  {"padded.png", "16384x16384 pixels of 64 bits", "bytes of image data can hold"});
  // Control characters of a scene file reach the message escaped, on one line.
  spit(dir_ / "nl.json", "{\"meshes\":[{\"file\":\"good.ply\"}],\"bad\\nkey\":1}");
  expect_rejected("a JSON key with a newline", "build nl.json", {"nl.json", "bad\\nkey"});
}

TEST_F(BadInput, CamerasAnimationsAndOutputsThatCannotWork) {
  // Lens values outside the --focal range and positions past valid rays'
  // coordinates rendered a blank image with exit 0.
  spit(dir_ / "f.json",
       "{\"meshes\":[{\"file\":\"good.ply\"}],\"camera\":{\"position\":[0,0,5],"
       "\"look_at\":[0,0,0],\"focal_length_mm\":1e-30}}");
  expect_rejected("camera focal length 1e-30 mm", "render f.json -o out.png",
                  {"f.json", "camera.focal_length_mm"});
  spit(dir_ / "p.json",
       "{\"meshes\":[{\"file\":\"good.ply\"}],\"camera\":{\"position\":[0,0,1e38],"
       "\"look_at\":[0,0,0]}}");
  expect_rejected("camera at z = 1e38", "render p.json -o out.png", {"p.json", "camera.position"});
  expect_rejected("--width x --height of 4.3 G pixels",
                  "render good.ply --width 65536 --height 65536 -o out.png", {"65536x65536"});
  // Animation fields checked when the scene is read, naming the field.
  spit(dir_ / "frame_0.ply", std::string(kPlyHead) + kTriangleData);
  const std::pair<std::string, std::string> anims[] = {
      {"\"sequences\":[{\"pattern\":\"frame_%s.ply\"}]", "a % must start %d"},
      {"\"sequences\":[{\"pattern\":\"good.ply\"}]", "has no frame number"},
      {"\"sequences\":[{\"pattern\":\"frame_%d.ply\"}],\"deformers\":[{\"kind\":\"wave\"}]",
       "has deformers too"}};
  for (const auto& [fields, problem] : anims) {
    spit(dir_ / "a.json",
         "{\"meshes\":[{\"file\":\"good.ply\"}],\"animation\":{\"frames\":2," + fields + "}}");
    expect_rejected("animation " + fields, "build a.json",
                    {"a.json", "animation.sequences[0]", problem});
  }
  // Outputs that name a directory or nothing fail before the work.
  fs::create_directory(dir_ / "out.hits");
  fs::create_directory(dir_ / "out.png");
  ASSERT_EQ(run("rays good.ply --kind random -n 10 -o r.rays").code, 0);
  expect_rejected("-o naming a directory", "trace good.ply --rays r.rays -o out.hits",
                  {"out.hits", "is a directory"});
  expect_rejected("an image -o naming a directory", "render good.ply -o out.png",
                  {"out.png", "is a directory"});
  expect_rejected("-o ''", "trace good.ply --rays r.rays -o ''", {"output path", "empty"});
  // generate writes binary PLY only: another name would not read back.
  expect_rejected("generate -o x.obj", "generate sphere --tris 100 -o x.obj", {"x.obj", ".ply"});
  expect_rejected("generate -o x.ply.gz", "generate sphere --tris 100 -o x.ply.gz", {"x.ply.gz"});
}

TEST_F(BadInput, ObjLinesThatDoNotParse) {
  spit(dir_ / "a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
  expect_rejected("OBJ face 'f 1 2 x'", "build a.obj", {"a.obj", "line 4"});
  spit(dir_ / "b.obj", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
  expect_rejected("OBJ vertex 'v 1 zero 0'", "build b.obj", {"b.obj", "line 2"});
  std::string junk = "v 0 0 0\nv 1 0 0\n";
  for (int i = 0; i < 256; ++i) junk += char((i * 37 + 11) & 0xff);
  spit(dir_ / "c.obj", junk);
  expect_rejected("OBJ with binary junk after line 2", "build c.obj", {"c.obj", "line 3"});
  spit(dir_ / "d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
  expect_rejected("OBJ face with 2 vertices", "build d.obj", {"d.obj", "line 4"});
}

TEST_F(BadInput, SceneJsonWrongTypesAndMissingFields) {
  spit(dir_ / "a.json", R"({"camera": {"width": "big"}, "meshes": []})");
  expect_rejected("JSON camera.width a string", "render a.json -o out.png", {"camera.width"});
  spit(dir_ / "b.json", R"({"camera": {"width": 64}})");
  expect_rejected("JSON without 'meshes'", "render b.json -o out.png", {"b.json", "meshes"});
  spit(dir_ / "c.json", R"({"meshes": [{"file": "good.ply", "material": {"diffuse": [1, 2]}}]})");
  expect_rejected("JSON diffuse with 2 components", "render c.json -o out.png",
                  {"meshes[0].material.diffuse"});
  spit(dir_ / "d.json", R"({"meshes": [{"file": "good.ply"}], "lightz": []})");
  expect_rejected("JSON unknown field 'lightz'", "render d.json -o out.png", {"lightz"});
  spit(dir_ / "e.json", R"({"meshes": [{"file": "missing.ply"}]})");
  expect_rejected("JSON mesh file that does not exist", "render e.json -o out.png",
                  {"missing.ply"});
  spit(dir_ / "f.json", R"({"meshes": [ {"file": "good.ply"} )");
  expect_rejected("JSON cut short", "render f.json -o out.png", {"f.json"});
  spit(dir_ / "g.json", R"({"max_depth": -1, "meshes": [{"file": "good.ply"}]})");
  expect_rejected("JSON max_depth -1", "render g.json -o out.png", {"max_depth"});
}

TEST_F(BadInput, RayFilesOfTheWrongSize) {
  spit(dir_ / "a.rays", std::string(33, '\0'));
  expect_rejected("33-byte .rays file", "trace good.ply --rays a.rays -o out.hits",
                  {"a.rays", "33"});
  spit(dir_ / "b.rays", std::string(31, '\0'));
  expect_rejected("31-byte .rays file", "validate rays good.ply --rays b.rays", {"b.rays"});
  expect_rejected("missing .rays file", "trace good.ply --rays none.rays -o out.hits",
                  {"none.rays"});
}

TEST_F(BadInput, OutputPathsThatCannotBeWritten) {
  expect_rejected("render into a missing directory", "render good.ply -o nodir/out.png",
                  {"nodir/out.png"});
  expect_rejected("trace into a missing directory",
                  "trace good.ply --rays good.ply -o nodir/out.hits", {});
  expect_rejected("rays into a path under a regular file",
                  "rays good.ply --kind random -n 10 -o good.ply/out.rays", {"good.ply/out.rays"});
  expect_rejected("generate into a path under a regular file",
                  "generate sphere --tris 100 -o good.ply/out.ply", {"good.ply/out.ply"});
  expect_rejected("render with an unknown image extension", "render good.ply -o out.xyz",
                  {"out.xyz"});
}

TEST_F(BadInput, OutputIntoReadOnlyDirectory) {
  fs::create_directories(dir_ / "ro");
  fs::permissions(dir_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  // Root (or CAP_DAC_OVERRIDE) may write into a mode-0500 directory; sysfs
  // refuses new files to everyone, so it stands in for the read-only directory.
  const bool ro_writable = ::access((dir_ / "ro").c_str(), W_OK) == 0;
  const std::string ro = ro_writable ? "/sys" : "ro";
  if (ro_writable) {
    ASSERT_FALSE(fs::exists("/sys/out.png") || fs::exists("/sys/out.rays"));
  }
  expect_rejected("render into a read-only directory", "render good.ply -o " + ro + "/out.png",
                  {ro + "/out.png"});
  expect_rejected("rays into a read-only directory",
                  "rays good.ply --kind random -n 10 -o " + ro + "/out.rays", {ro + "/out.rays"});
  if (ro_writable) {
    EXPECT_FALSE(fs::exists("/sys/out.png"));
    EXPECT_FALSE(fs::exists("/sys/out.rays"));
  }
}

TEST_F(BadInput, AbsurdOptions) {
  expect_rejected("--threads -1", "render good.ply --threads -1 -o out.png", {"--threads"});
  expect_rejected("--threads 100000", "build good.ply --threads 100000", {"--threads"});
  expect_rejected("--bins 1", "build good.ply --bins 1", {"--bins"});
  expect_rejected("--bins 0", "render good.ply --bins 0 -o out.png", {"--bins"});
  expect_rejected("--leaf-size 0", "build good.ply --leaf-size 0", {"--leaf-size"});
  expect_rejected("--leaf-size -4", "render good.ply --leaf-size -4 -o out.png", {"--leaf-size"});
  expect_rejected("--sah-traversal -1", "build good.ply --sah-traversal -1", {"--sah-traversal"});
  expect_rejected("--sah-traversal inf", "build good.ply --sah-traversal inf", {"--sah-traversal"});
  expect_rejected("--sah-traversal nan", "build good.ply --sah-traversal nan", {"--sah-traversal"});
  expect_rejected("--sah-traversal nan (embree)",
                  "render good.ply --backend embree --sah-traversal nan -o out.png",
                  {"--sah-traversal"});
  expect_rejected("--adaptive-factor nan", "render good.ply --adaptive-factor nan -o out.png",
                  {"--adaptive-factor"});
  expect_rejected("--sah-intersection 0", "trace good.ply --sah-intersection 0 --rays r -o o",
                  {"--sah-intersection"});
  expect_rejected("--sah-leaf-block 0", "build good.ply --sah-leaf-block 0", {"--sah-leaf-block"});
  expect_rejected("--sah-leaf-block 65", "trace good.ply --sah-leaf-block 65 --rays r -o o",
                  {"--sah-leaf-block"});
  expect_rejected("--width 0", "render good.ply --width 0 -o out.png", {"--width"});
  expect_rejected("--width -5", "render good.ply --width -5 -o out.png", {"--width"});
  expect_rejected("--height 0", "render good.ply --height 0 -o out.png", {"--height"});
  expect_rejected("--width 1000000", "render good.ply --width 1000000 -o out.png", {"--width"});
  expect_rejected("-n 1e12 (rays)", "rays good.ply --kind random -n 1e12 -o out.rays", {"-n"});
  expect_rejected("-n 1e12 (validate rays)", "validate rays good.ply --kind random -n 1e12",
                  {"-n"});
  expect_rejected("-n 0", "rays good.ply --kind random -n 0 -o out.rays", {"-n"});
  expect_rejected("-n -5", "rays good.ply --kind random -n -5 -o out.rays", {"-n"});
  expect_rejected("-n 2.5", "rays good.ply --kind random -n 2.5 -o out.rays", {"-n"});
  expect_rejected("--tris 0", "generate sphere --tris 0 -o out.ply", {"--tris"});
  expect_rejected("--tris 1e12", "generate sphere --tris 1e12 -o out.ply", {"--tris"});
  expect_rejected("unknown --kind", "rays good.ply --kind laser -n 10 -o out.rays", {"laser"});
  expect_rejected("unknown --builder", "build good.ply --builder magic", {"--builder"});
  expect_rejected("unknown --layout", "render good.ply --layout bvh16 -o out.png", {"--layout"});
  expect_rejected("unknown bench --layout", "bench trace good.ply --quick --layout bvh3",
                  {"--layout"});
  expect_rejected("unknown --backend", "render good.ply --backend optix -o out.png", {"--backend"});
  expect_rejected("--frames 5:2", "render good.ply --frames 5:2 -o out_%04d.png", {"--frames"});
}

// Non-finite vertices: their triangles are dropped and counted; the rest
// builds, traces and renders.
TEST_F(BadInput, NonFiniteCoordinatesAreDroppedAndCounted) {
  spit(dir_ / "nan.ply",
       "ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\n"
       "property float z\nelement face 3\nproperty list uchar int vertex_indices\nend_header\n"
       "-1 -1 0\n1 -1 0\n0 1 0\nnan 0 0\n1 0 0\n0 1 0\n0 0 0\n1 inf 0\n0 -inf 1\n"
       "3 0 1 2\n3 3 4 5\n3 6 7 8\n");
  const CliResult b = run("build nan.ply --json");
  ASSERT_EQ(b.code, 0) << b.err;
  const auto j = nlohmann::json::parse(b.out);
  EXPECT_EQ(j.at("triangles").get<int>(), 1);
  EXPECT_EQ(j.at("invalid_triangles").get<int>(), 2);
  log("PLY with 2 of 3 triangles non-finite (build)", "build nan.ply --json", b);

  const CliResult r = run("render nan.ply --width 32 --height 32 -o nan.exr");
  log("PLY with 2 of 3 triangles non-finite (render)", "render nan.ply -o nan.exr", r);
  ASSERT_EQ(r.code, 0) << r.err;
  const Image img = read_image(path("nan.exr"));
  ASSERT_EQ(img.width, 32);
  // The framed camera looks at the one valid triangle: the centre pixel hits it.
  int lit = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) lit += img.at(x, y, 0) > 0.15f ? 1 : 0;
  EXPECT_GT(lit, 10);
}

// A scene with no meshes renders the background everywhere and misses every
// ray. (A mesh *file* with no faces stays an error: it is a point cloud or
// the wrong file, see MeshReader.MeshWithoutTrianglesIsError.)
TEST_F(BadInput, EmptySceneRendersBackgroundAndMissesEverything) {
  spit(dir_ / "empty.json", R"({"camera": {"width": 40, "height": 30},
      "background": [0.25, 0.5, 0.75], "meshes": []})");
  const CliResult r = run("render empty.json -o bg.exr --json");
  log("scene with no meshes (render)", "render empty.json -o bg.exr --json", r);
  ASSERT_EQ(r.code, 0) << r.err;
  const Image img = read_image(path("bg.exr"));
  ASSERT_EQ(img.width, 40);
  ASSERT_EQ(img.height, 30);
  int wrong = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      wrong +=
          (img.at(x, y, 0) == 0.25f && img.at(x, y, 1) == 0.5f && img.at(x, y, 2) == 0.75f) ? 0 : 1;
  EXPECT_EQ(wrong, 0);

  spit(dir_ / "nothing.json", R"({"meshes": []})");
  ASSERT_EQ(run("rays good.ply --kind random -n 500 -o r.rays").code, 0);
  for (const std::string backend : {"bvh", "embree"}) {
    const CliResult t = run("trace nothing.json --rays r.rays --backend " + backend + " -o " +
                            backend + ".hits --json");
    log("scene with no meshes (trace " + backend + ")",
        "trace nothing.json --rays r.rays --backend " + backend + " --json", t);
    ASSERT_EQ(t.code, 0) << t.err;
    EXPECT_EQ(nlohmann::json::parse(t.out).at("hits").get<int>(), 0);
    const std::vector<Hit> hits = read_hits(path(backend + ".hits"));
    ASSERT_EQ(hits.size(), 500u);
    for (const Hit& h : hits) {
      EXPECT_FALSE(h.hit());
      EXPECT_TRUE(std::isinf(h.t));
    }
  }
  // Every triangle non-finite: an empty scene too.
  spit(dir_ / "allnan.ply", std::string(kPlyHead) + "nan 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const CliResult n = run("render allnan.ply --width 16 --height 16 -o allnan.png");
  log("mesh whose only triangle is non-finite (render)", "render allnan.ply -o allnan.png", n);
  EXPECT_EQ(n.code, 0) << n.err;
  EXPECT_TRUE(fs::exists(dir_ / "allnan.png"));
}

TEST_F(BadInput, MeshFileWithoutFacesIsAnError) {
  spit(dir_ / "points.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
  expect_rejected("PLY point cloud (no face element)", "render points.ply -o out.png",
                  {"points.ply"});
  spit(dir_ / "empty.obj", "");
  expect_rejected("empty OBJ file", "build empty.obj", {"empty.obj"});
}

}  // namespace
}  // namespace hprt
