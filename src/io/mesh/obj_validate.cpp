// OBJ syntax check: one pass over the lines with std::from_chars; no
// allocation per line. Statement list from the Wavefront OBJ specification
// (Appendix B1 of the Advanced Visualizer manual) plus tinyobjloader's vw/t.
#include "io/mesh/obj_validate.h"

#include <charconv>
#include <cmath>
#include <cstdlib>

#include "core/error.h"

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

constexpr std::string_view kIgnoredStatements[] = {
    "o",     "g",     "s",      "mg",         "usemtl",    "mtllib", "usemap",   "maplib",
    "lod",   "l",     "p",      "shadow_obj", "trace_obj", "bevel",  "c_interp", "d_interp",
    "ctech", "stech", "cstype", "deg",        "bmat",      "step",   "curv",     "curv2",
    "surf",  "parm",  "trim",   "hole",       "scrv",      "sp",     "end",      "con",
    "call",  "csh",   "vw",     "t"};

bool is_blank(char c) { return c == ' ' || c == '\t'; }

class LineCheck {
 public:
  LineCheck(const std::string& path, size_t line) : path_(path), line_(line) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(path_, "line " + std::to_string(line_) + ": " + problem);
  }

  static std::string_view next_word(std::string_view* rest) {
    size_t i = 0;
    while (i < rest->size() && is_blank((*rest)[i])) ++i;
    size_t j = i;
    while (j < rest->size() && !is_blank((*rest)[j])) ++j;
    const std::string_view w = rest->substr(i, j - i);
    rest->remove_prefix(j);
    return w;
  }

  double number(std::string_view w) const {
    std::string_view s = w;
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    double v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || r.ptr != s.data() + s.size()) fail(quoted(w, "is not a number"));
    if (r.ec == std::errc::result_out_of_range) v = std::strtod(std::string(s).c_str(), nullptr);
    return v;
  }

  // Reads between lo and hi numbers; returns how many, the first 3 in out.
  int numbers(std::string_view rest, int lo, int hi, std::string_view what, double* out) const {
    int n = 0;
    for (std::string_view w = next_word(&rest); !w.empty(); w = next_word(&rest)) {
      const double v = number(w);
      if (n < 3) out[n] = v;
      ++n;
    }
    if (n < lo || n > hi) {
      std::string msg(what);
      msg += " needs ";
      msg += std::to_string(lo);
      if (lo != hi) msg.append(" to ").append(std::to_string(hi));
      msg.append(" numbers, found ").append(std::to_string(n));
      fail(msg);
    }
    return n;
  }

  int64_t index(std::string_view s, std::string_view ref) const {
    int64_t v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size())
      fail(std::string("bad face vertex ") + quoted(ref, ""));
    if (v == 0) fail(std::string("face vertex ") + quoted(ref, "has index 0"));
    return v;
  }

 private:
  const std::string& path_;
  size_t line_;
};

// Largest positive (absolute) index seen for one attribute, and where.
struct MaxRef {
  int64_t index = 0;
  size_t line = 0;
  void see(int64_t i, size_t at) {
    if (i > index) index = i, line = at;
  }
};

}  // namespace

ObjTextSummary validate_obj_text(const std::string& path, std::string_view text) {
  ObjTextSummary sum;
  size_t texcoords = 0;
  MaxRef max_v, max_vt, max_vn;
  size_t pos = 0;
  size_t line_no = 0;
  while (pos < text.size()) {
    // Lines end at \n, \r\n or a lone \r, as tinyobjloader's safeGetline splits them.
    size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    std::string_view line = text.substr(pos, end - pos);
    pos = end;
    if (pos < text.size() && text[pos] == '\r') ++pos;
    if (pos < text.size() && text[pos] == '\n') ++pos;  // \n alone, or the \n of \r\n
    ++line_no;
    const LineCheck check(path, line_no);
    for (char c : line)
      if (static_cast<unsigned char>(c) < 0x20 && c != '\t')
        check.fail("binary data (byte 0x" + std::to_string(static_cast<unsigned char>(c)) +
                   ") in an OBJ file");
    std::string_view rest = line;
    const std::string_view kw = LineCheck::next_word(&rest);
    if (kw.empty() || kw[0] == '#') continue;
    double xyz[3] = {0, 0, 0};
    if (kw == "v") {
      check.numbers(rest, 3, 7, "v", xyz);
      if (!std::isfinite(static_cast<float>(xyz[0])) ||
          !std::isfinite(static_cast<float>(xyz[1])) || !std::isfinite(static_cast<float>(xyz[2])))
        sum.non_finite_vertices.push_back(
            {sum.vertices, Vec3f(static_cast<float>(xyz[0]), static_cast<float>(xyz[1]),
                                 static_cast<float>(xyz[2]))});
      ++sum.vertices;
    } else if (kw == "vn") {
      check.numbers(rest, 3, 3, "vn", xyz);
      ++sum.normals;
    } else if (kw == "vt") {
      check.numbers(rest, 1, 3, "vt", xyz);
      ++texcoords;
    } else if (kw == "vp") {
      check.numbers(rest, 1, 3, "vp", xyz);
    } else if (kw == "f") {
      size_t n = 0;
      for (std::string_view ref = LineCheck::next_word(&rest); !ref.empty();
           ref = LineCheck::next_word(&rest), ++n) {
        // ref = v | v/t | v//n | v/t/n
        std::string_view parts[3];
        int np = 0;
        size_t start = 0;
        for (size_t i = 0; i <= ref.size(); ++i)
          if (i == ref.size() || ref[i] == '/') {
            if (np == 3) check.fail(std::string("bad face vertex ") + quoted(ref, ""));
            parts[np++] = ref.substr(start, i - start);
            start = i + 1;
          }
        struct Attr {
          size_t count;
          MaxRef* max;
          const char* name;
        } attrs[3] = {{sum.vertices, &max_v, "vertex"},
                      {texcoords, &max_vt, "texcoord"},
                      {sum.normals, &max_vn, "normal"}};
        for (int k = 0; k < np; ++k) {
          if (k > 0 && parts[k].empty() && !(k == 1 && np == 3)) {
            check.fail(std::string("bad face vertex ") + quoted(ref, ""));
          }
          if (parts[k].empty()) continue;  // the t of v//n
          const int64_t i = check.index(parts[k], ref);
          if (i > 0) {
            attrs[k].max->see(i, line_no);
          } else if (static_cast<uint64_t>(-i) > attrs[k].count) {
            check.fail("face references " + std::string(attrs[k].name) + " " + std::to_string(i) +
                       " (relative) with only " + std::to_string(attrs[k].count) +
                       " defined before it");
          }
        }
      }
      if (n < 3) check.fail("face with " + std::to_string(n) + " vertices (at least 3 needed)");
      ++sum.faces;
      sum.triangles += n - 2;
    } else {
      bool known = false;
      for (std::string_view s : kIgnoredStatements) known = known || s == kw;
      if (!known) check.fail(std::string("unknown OBJ statement ") + quoted(kw, ""));
    }
  }
  const struct {
    const MaxRef& ref;
    size_t count;
    const char* name;
  } finals[3] = {{max_v, sum.vertices, "vertex"},
                 {max_vt, texcoords, "texcoord"},
                 {max_vn, sum.normals, "normal"}};
  for (const auto& f : finals)
    if (static_cast<uint64_t>(f.ref.index) > f.count)
      throw InputError(path, "line " + std::to_string(f.ref.line) + ": face references " + f.name +
                                 " " + std::to_string(f.ref.index) + " of " +
                                 std::to_string(f.count));
  return sum;
}

}  // namespace hprt
