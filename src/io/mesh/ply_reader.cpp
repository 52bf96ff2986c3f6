// PLY data section: sizes are checked against the header before anything is
// allocated, then each element is decoded by one loop templated on the
// encoding (binary with or without byte swapping, or ASCII tokens parsed with
// std::from_chars). Common binary layouts (float xyz, uchar+int face lists)
// take a fast path.
#include "io/mesh/ply_reader.h"

#include <bit>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "io/mesh/ply_header.h"

namespace hprt {
namespace {

// 'word' (at most 40 characters) followed by `what`, built without
// operator+ chains that trip GCC 12's -Wrestrict false positive.
std::string quoted(std::string_view word, std::string_view what) {
  std::string s(1, '\'');
  s.append(word.substr(0, 40)).append("'");
  if (!what.empty()) s.append(" ").append(what);
  return s;
}

template <typename T>
T byteswap_value(T v) {
  if constexpr (sizeof(T) == 1) {
    return v;
  } else {
    using U = std::conditional_t<sizeof(T) == 2, uint16_t,
                                 std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>;
    U u;
    std::memcpy(&u, &v, sizeof u);
    if constexpr (sizeof(T) == 2)
      u = __builtin_bswap16(u);
    else if constexpr (sizeof(T) == 4)
      u = __builtin_bswap32(u);
    else
      u = __builtin_bswap64(u);
    std::memcpy(&v, &u, sizeof v);
    return v;
  }
}

template <typename T, bool Swap>
T load(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  if constexpr (Swap) v = byteswap_value(v);
  return v;
}

// Where we are, for error messages.
struct Position {
  const std::string* path;
  const PlyElement* element = nullptr;
  uint64_t record = 0;

  [[noreturn]] void fail(const std::string& problem) const {
    std::string where;
    if (element) where = element->name + " " + std::to_string(record) + ": ";
    throw InputError(*path, where + problem);
  }
};

// Binary records; Swap when the file's byte order differs from the host's.
template <bool Swap>
class BinarySource {
 public:
  BinarySource(const char* p, const char* end, Position* at) : p_(p), end_(end), at_(at) {}

  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  const char* data() const { return p_; }
  void advance(size_t n) { p_ += n; }
  void require(size_t n) const {
    if (remaining() < n) at_->fail("truncated data (file ends inside the record)");
  }

  double real(PlyType t) {
    const size_t n = ply_type_size(t);
    require(n);
    const double v = real_at(p_, t);
    p_ += n;
    return v;
  }
  int64_t integer(PlyType t) {
    const size_t n = ply_type_size(t);
    require(n);
    const int64_t v = integer_at(p_, t);
    p_ += n;
    return v;
  }
  void skip(PlyType t) {
    require(ply_type_size(t));
    p_ += ply_type_size(t);
  }
  void skip_items(uint64_t n, PlyType t) { p_ += n * ply_type_size(t); }  // after list_count
  // Reads a list count and checks that its items fit in the rest of the file.
  uint64_t list_count(PlyType count_type, PlyType item_type) {
    const int64_t n = integer(count_type);
    if (n < 0) at_->fail("negative list count " + std::to_string(n));
    if (static_cast<uint64_t>(n) > remaining() / ply_type_size(item_type))
      at_->fail("list count " + std::to_string(n) + " exceeds the remaining data");
    return static_cast<uint64_t>(n);
  }

  static double real_at(const char* p, PlyType t) {
    switch (t) {
      case PlyType::kInt8:
        return load<int8_t, Swap>(p);
      case PlyType::kUint8:
        return load<uint8_t, Swap>(p);
      case PlyType::kInt16:
        return load<int16_t, Swap>(p);
      case PlyType::kUint16:
        return load<uint16_t, Swap>(p);
      case PlyType::kInt32:
        return load<int32_t, Swap>(p);
      case PlyType::kUint32:
        return load<uint32_t, Swap>(p);
      case PlyType::kFloat32:
        return load<float, Swap>(p);
      case PlyType::kFloat64:
        return load<double, Swap>(p);
    }
    return 0;
  }
  static int64_t integer_at(const char* p, PlyType t) {
    switch (t) {
      case PlyType::kInt8:
        return load<int8_t, Swap>(p);
      case PlyType::kUint8:
        return load<uint8_t, Swap>(p);
      case PlyType::kInt16:
        return load<int16_t, Swap>(p);
      case PlyType::kUint16:
        return load<uint16_t, Swap>(p);
      case PlyType::kInt32:
        return load<int32_t, Swap>(p);
      case PlyType::kUint32:
        return load<uint32_t, Swap>(p);
      default:
        return 0;  // float index types are rejected before reading
    }
  }

 private:
  const char* p_;
  const char* end_;
  Position* at_;
};

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// ASCII records: whitespace-separated tokens (line breaks are not significant).
class AsciiSource {
 public:
  AsciiSource(const char* p, const char* end, Position* at) : p_(p), end_(end), at_(at) {}

  size_t remaining() const { return static_cast<size_t>(end_ - p_); }

  double real(PlyType t) {
    std::string_view tok = token();
    if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
    if (t == PlyType::kFloat32) {
      float v = 0;
      const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      if (r.ptr != tok.data() + tok.size() || tok.empty()) bad_number(tok);
      if (r.ec == std::errc::result_out_of_range) return out_of_range(tok);
      return v;
    }
    double v = 0;
    const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (r.ptr != tok.data() + tok.size() || tok.empty()) bad_number(tok);
    if (r.ec == std::errc::result_out_of_range) return out_of_range(tok);
    return v;
  }
  int64_t integer(PlyType) {
    std::string_view tok = token();
    if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
    int64_t v = 0;
    const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (r.ec != std::errc() || r.ptr != tok.data() + tok.size() || tok.empty())
      at_->fail(quoted(tok, "is not an integer"));
    return v;
  }
  void skip(PlyType) { token(); }
  void skip_items(uint64_t n, PlyType) {
    for (uint64_t i = 0; i < n; ++i) token();
  }
  uint64_t list_count(PlyType count_type, PlyType) {
    const int64_t n = integer(count_type);
    if (n < 0) at_->fail("negative list count " + std::to_string(n));
    // Every ASCII item takes at least one character and one separator.
    if (static_cast<uint64_t>(n) > remaining() / 2 + 1)
      at_->fail("list count " + std::to_string(n) + " exceeds the remaining data");
    return static_cast<uint64_t>(n);
  }

 private:
  std::string_view token() {
    while (p_ < end_ && is_space(*p_)) ++p_;
    if (p_ == end_) at_->fail("truncated data (file ends inside the record)");
    const char* start = p_;
    while (p_ < end_ && !is_space(*p_)) ++p_;
    return {start, static_cast<size_t>(p_ - start)};
  }
  [[noreturn]] void bad_number(std::string_view tok) const {
    at_->fail(quoted(tok, "is not a number"));
  }
  // from_chars reports overflow and underflow alike; strtod tells them apart.
  static double out_of_range(std::string_view tok) {
    const std::string s(tok);
    return std::strtod(s.c_str(), nullptr);
  }

  const char* p_;
  const char* end_;
  Position* at_;
};

enum class Role { kVertex, kFace, kStrips, kOther };

struct VertexLayout {
  int xyz[3] = {-1, -1, -1};
  int nxyz[3] = {-1, -1, -1};
  bool has_normals() const { return nxyz[0] >= 0 && nxyz[1] >= 0 && nxyz[2] >= 0; }
};

class PlyDecoder {
 public:
  PlyDecoder(const std::string& path, TriangleMesh* mesh) : path_(path), mesh_(mesh) {
    at_.path = &path_;
  }

  // Reads every element in file order from `src`.
  template <typename Source>
  void read_elements(const PlyHeader& h, Source& src, const VertexLayout& layout) {
    for (const PlyElement& e : h.elements) {
      at_.element = &e;
      at_.record = 0;
      if (e.properties.empty()) continue;  // records without data
      const Role role = role_of(e);
      if (role == Role::kVertex)
        read_vertices(e, src, layout);
      else if (role == Role::kFace || role == Role::kStrips)
        read_polygons(e, src, role);
      else
        skip_element(e, src);
    }
  }

  Position& at() { return at_; }

 private:
  Role role_of(const PlyElement& e) const {
    if (e.name == "vertex") return Role::kVertex;
    if (e.name == "face") return Role::kFace;
    if (e.name == "tristrips") return Role::kStrips;
    return Role::kOther;
  }

  // The index list of a face or tristrips element.
  int index_list(const PlyElement& e) const {
    for (const char* name : {"vertex_indices", "vertex_index"}) {
      const int i = e.find(name);
      if (i >= 0 && e.properties[i].is_list) return i;
    }
    if (e.name == "tristrips")
      for (size_t i = 0; i < e.properties.size(); ++i)
        if (e.properties[i].is_list) return static_cast<int>(i);
    return -1;
  }

  template <typename Source>
  void skip_element(const PlyElement& e, Source& src) {
    for (at_.record = 0; at_.record < e.count; ++at_.record) skip_record(e, src);
  }

  template <typename Source>
  void skip_record(const PlyElement& e, Source& src) {
    for (const PlyProperty& p : e.properties) {
      if (p.is_list)
        src.skip_items(src.list_count(p.count_type, p.type), p.type);
      else
        src.skip(p.type);
    }
  }

  template <typename Source>
  void read_vertices(const PlyElement& e, Source& src, const VertexLayout& layout) {
    Vec3f* pos = mesh_->positions.data();
    Vec3f* nrm = layout.has_normals() ? mesh_->normals.data() : nullptr;
    if constexpr (!std::is_same_v<Source, AsciiSource>) {
      if (!e.has_list()) {
        read_vertices_fixed(e, src, layout, pos, nrm);
        return;
      }
    }
    for (at_.record = 0; at_.record < e.count; ++at_.record) {
      const size_t v = static_cast<size_t>(at_.record);
      for (size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& p = e.properties[i];
        if (p.is_list) {
          src.skip_items(src.list_count(p.count_type, p.type), p.type);
          continue;
        }
        const int k = static_cast<int>(i);
        if (k == layout.xyz[0])
          pos[v].x = static_cast<float>(src.real(p.type));
        else if (k == layout.xyz[1])
          pos[v].y = static_cast<float>(src.real(p.type));
        else if (k == layout.xyz[2])
          pos[v].z = static_cast<float>(src.real(p.type));
        else if (nrm && k == layout.nxyz[0])
          nrm[v].x = static_cast<float>(src.real(p.type));
        else if (nrm && k == layout.nxyz[1])
          nrm[v].y = static_cast<float>(src.real(p.type));
        else if (nrm && k == layout.nxyz[2])
          nrm[v].z = static_cast<float>(src.real(p.type));
        else
          src.skip(p.type);
      }
    }
  }

  // Binary vertex records of fixed size: one bounds check, then strided loads.
  template <typename Source>
  void read_vertices_fixed(const PlyElement& e, Source& src, const VertexLayout& layout, Vec3f* pos,
                           Vec3f* nrm) {
    const size_t rec = e.min_binary_record_bytes();
    if (e.count > src.remaining() / rec) {
      at_.record = src.remaining() / rec;
      at_.fail("truncated data (file ends inside the record)");
    }
    size_t offset[6] = {0, 0, 0, 0, 0, 0};
    PlyType type[6] = {PlyType::kFloat32, PlyType::kFloat32, PlyType::kFloat32,
                       PlyType::kFloat32, PlyType::kFloat32, PlyType::kFloat32};
    size_t off = 0;
    for (size_t i = 0; i < e.properties.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        if (static_cast<int>(i) == layout.xyz[k]) offset[k] = off, type[k] = e.properties[i].type;
        if (static_cast<int>(i) == layout.nxyz[k])
          offset[3 + k] = off, type[3 + k] = e.properties[i].type;
      }
      off += ply_type_size(e.properties[i].type);
    }
    const char* base = src.data();
    const size_t n = static_cast<size_t>(e.count);
    constexpr bool kSwap = std::is_same_v<Source, BinarySource<true>>;
    const bool all_float = type[0] == PlyType::kFloat32 && type[1] == PlyType::kFloat32 &&
                           type[2] == PlyType::kFloat32;
    if (all_float) {
      for (size_t v = 0; v < n; ++v) {
        const char* r = base + v * rec;
        pos[v] = {load<float, kSwap>(r + offset[0]), load<float, kSwap>(r + offset[1]),
                  load<float, kSwap>(r + offset[2])};
      }
    } else {
      for (size_t v = 0; v < n; ++v) {
        const char* r = base + v * rec;
        for (int k = 0; k < 3; ++k)
          pos[v][k] = static_cast<float>(Source::real_at(r + offset[k], type[k]));
      }
    }
    if (nrm)
      for (size_t v = 0; v < n; ++v) {
        const char* r = base + v * rec;
        for (int k = 0; k < 3; ++k)
          nrm[v][k] = static_cast<float>(Source::real_at(r + offset[3 + k], type[3 + k]));
      }
    src.advance(n * rec);
  }

  template <typename Source>
  void read_polygons(const PlyElement& e, Source& src, Role role) {
    const int list = index_list(e);
    if (list < 0) at_.fail("element has no vertex_indices list property");
    const PlyProperty& lp = e.properties[list];
    if (!ply_type_is_integer(lp.type)) at_.fail("vertex index type must be an integer type");
    mesh_->triangles.reserve(mesh_->triangles.size() + static_cast<size_t>(e.count));
    if constexpr (!std::is_same_v<Source, AsciiSource>) {
      if (role == Role::kFace && e.properties.size() == 1 && lp.count_type == PlyType::kUint8 &&
          (lp.type == PlyType::kInt32 || lp.type == PlyType::kUint32)) {
        read_faces_uchar_int(e, src, lp.type);
        return;
      }
    }
    for (at_.record = 0; at_.record < e.count; ++at_.record) {
      for (size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& p = e.properties[i];
        if (!p.is_list) {
          src.skip(p.type);
          continue;
        }
        const uint64_t n = src.list_count(p.count_type, p.type);
        if (static_cast<int>(i) != list) {
          src.skip_items(n, p.type);
          continue;
        }
        poly_.resize(static_cast<size_t>(n));
        for (size_t k = 0; k < poly_.size(); ++k) poly_[k] = src.integer(p.type);
        if (role == Role::kFace)
          emit_fan();
        else
          emit_strip();
      }
    }
  }

  // The most common binary face layout: `list uchar int|uint vertex_indices`.
  template <typename Source>
  void read_faces_uchar_int(const PlyElement& e, Source& src, PlyType index_type) {
    constexpr bool kSwap = std::is_same_v<Source, BinarySource<true>>;
    const bool is_signed = index_type == PlyType::kInt32;
    const char* p = src.data();
    const char* end = p + src.remaining();
    const uint64_t nv = mesh_->positions.size();
    for (at_.record = 0; at_.record < e.count; ++at_.record) {
      if (p == end) at_.fail("truncated data (file ends inside the record)");
      const size_t n = static_cast<unsigned char>(*p++);
      if (static_cast<size_t>(end - p) < 4 * n)
        at_.fail("truncated data (file ends inside the record)");
      if (n == 3) {
        uint32_t t[3];
        for (int k = 0; k < 3; ++k) {
          const uint32_t u = load<uint32_t, kSwap>(p + 4 * k);
          const int64_t idx = is_signed ? int64_t(int32_t(u)) : int64_t(u);
          if (idx < 0 || static_cast<uint64_t>(idx) >= nv) bad_index(idx);
          t[k] = static_cast<uint32_t>(idx);
        }
        mesh_->triangles.push_back(Vec3u{{t[0], t[1], t[2]}});
      } else {
        poly_.resize(n);
        for (size_t k = 0; k < n; ++k) {
          const uint32_t u = load<uint32_t, kSwap>(p + 4 * k);
          poly_[k] = is_signed ? int64_t(int32_t(u)) : int64_t(u);
        }
        emit_fan();
      }
      p += 4 * n;
    }
    src.advance(static_cast<size_t>(p - src.data()));
  }

  [[noreturn]] void bad_index(int64_t idx) const {
    at_.fail("references vertex " + std::to_string(idx) + " of " +
             std::to_string(mesh_->positions.size()));
  }

  void emit_fan() {
    // As the OBJ reader: a face of 0-2 vertices is a broken file, not a
    // polygon to skip.
    if (poly_.size() < 3)
      at_.fail("face with " + std::to_string(poly_.size()) + " vertices (at least 3 needed)");
    const uint64_t nv = mesh_->positions.size();
    for (int64_t idx : poly_)
      if (idx < 0 || static_cast<uint64_t>(idx) >= nv) bad_index(idx);
    for (size_t k = 1; k + 1 < poly_.size(); ++k)
      mesh_->triangles.push_back(
          Vec3u{{static_cast<uint32_t>(poly_[0]), static_cast<uint32_t>(poly_[k]),
                 static_cast<uint32_t>(poly_[k + 1])}});
  }

  void emit_strip() {
    const uint64_t nv = mesh_->positions.size();
    size_t run_start = 0;
    for (size_t k = 0; k <= poly_.size(); ++k) {
      if (k < poly_.size() && poly_[k] != -1) {
        if (poly_[k] < 0 || static_cast<uint64_t>(poly_[k]) >= nv) bad_index(poly_[k]);
        continue;
      }
      // Run [run_start, k): triangle j is (s_j, s_j+1, s_j+2), odd ones flipped.
      for (size_t j = run_start; j + 2 < k; ++j) {
        uint32_t a = static_cast<uint32_t>(poly_[j]);
        uint32_t b = static_cast<uint32_t>(poly_[j + 1]);
        const uint32_t c = static_cast<uint32_t>(poly_[j + 2]);
        if (a == b || b == c || a == c) continue;  // a joint between strip pieces
        if ((j - run_start) & 1) std::swap(a, b);
        mesh_->triangles.push_back(Vec3u{{a, b, c}});
      }
      run_start = k + 1;
    }
  }

  const std::string& path_;
  TriangleMesh* mesh_;
  Position at_;
  std::vector<int64_t> poly_;
};

// The smallest encoding of every record must fit in the data, else the header
// lies: checked before any allocation sized by a header count.
void check_sizes(const std::string& path, const PlyHeader& h, size_t available) {
  const bool ascii = h.format == PlyFormat::kAscii;
  // ASCII: each value needs a character and a separator (the very last one
  // may lack its separator), hence 2 * values <= available + 1.
  uint64_t budget = ascii ? static_cast<uint64_t>(available) + 1 : available;
  for (const PlyElement& e : h.elements) {
    const uint64_t per = ascii ? 2 * e.properties.size() : e.min_binary_record_bytes();
    if (per == 0) continue;
    if (e.count > budget / per)
      throw InputError(path, "header declares " + std::to_string(e.count) + " " + e.name +
                                 " records but the file holds only " + std::to_string(available) +
                                 " bytes of data");
    budget -= e.count * per;
  }
}

}  // namespace

TriangleMesh read_ply(const std::string& path, std::string_view bytes) {
  const PlyHeader h = parse_ply_header(path, bytes);
  const size_t available = bytes.size() - h.data_offset;
  check_sizes(path, h, available);

  const PlyElement* vertex = nullptr;
  bool has_polygons = false;
  for (const PlyElement& e : h.elements) {
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "face" || e.name == "tristrips") has_polygons = true;
  }
  if (!vertex) throw InputError(path, "PLY file has no vertex element");
  if (!has_polygons) throw InputError(path, "PLY file has no face or tristrips element");
  const char* names[6] = {"x", "y", "z", "nx", "ny", "nz"};
  VertexLayout layout;
  for (int k = 0; k < 6; ++k) {
    const int i = vertex->find(names[k]);
    if (i >= 0 && vertex->properties[i].is_list)
      throw InputError(path, std::string("vertex property ") + names[k] + " is a list");
    (k < 3 ? layout.xyz[k] : layout.nxyz[k - 3]) = i;
  }
  for (int k = 0; k < 3; ++k)
    if (layout.xyz[k] < 0)
      throw InputError(path, std::string("vertex element has no ") + names[k] + " property");
  // A repeated vertex element would be ambiguous; faces index the first one.
  for (const PlyElement& e : h.elements)
    if (e.name == "vertex" && &e != vertex)
      throw InputError(path, "PLY file has more than one vertex element");

  TriangleMesh mesh;
  mesh.name = path;
  mesh.positions.resize(static_cast<size_t>(vertex->count));
  if (layout.has_normals()) mesh.normals.resize(static_cast<size_t>(vertex->count));

  PlyDecoder decoder(path, &mesh);
  const char* begin = bytes.data() + h.data_offset;
  const char* end = bytes.data() + bytes.size();
  const bool big_host = std::endian::native == std::endian::big;
  if (h.format == PlyFormat::kAscii) {
    AsciiSource src(begin, end, &decoder.at());
    decoder.read_elements(h, src, layout);
  } else if ((h.format == PlyFormat::kBinaryBigEndian) != big_host) {
    BinarySource<true> src(begin, end, &decoder.at());
    decoder.read_elements(h, src, layout);
  } else {
    BinarySource<false> src(begin, end, &decoder.at());
    decoder.read_elements(h, src, layout);
  }
  return mesh;
}

}  // namespace hprt
