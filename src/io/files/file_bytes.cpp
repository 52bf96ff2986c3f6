// Whole-file reads with transparent gzip decompression (zlib inflate with
// automatic gzip header detection), bounded by a size limit.
#include "io/files/file_bytes.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/error.h"

namespace hprt {
namespace {

char lower(char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; }

bool ends_with_nocase(std::string_view s, std::string_view suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i)
    if (lower(s[s.size() - suffix.size() + i]) != suffix[i]) return false;
  return true;
}

std::string size_text(size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

// Owns a file descriptor for the duration of a read.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string read_plain(const std::string& path, size_t limit) {
  // O_NONBLOCK: opening a FIFO would otherwise wait for a writer; a regular
  // file reads the same either way.
  Fd f{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)};
  if (f.fd < 0) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0)
    throw InputError(path, std::string("cannot read: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw InputError(path, "cannot open: Is a directory");
  if (!S_ISREG(st.st_mode)) throw InputError(path, "not a regular file");
  if (st.st_size < 0 || static_cast<uint64_t>(st.st_size) > limit)
    throw InputError(path, "file is larger than the " + size_text(limit) + " limit");
  std::string data(static_cast<size_t>(st.st_size), '\0');
  size_t got = 0;
  while (got < data.size()) {
    const ssize_t n = ::read(f.fd, data.data() + got, data.size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(path, std::string("cannot read: ") + std::strerror(errno));
    }
    if (n == 0) break;  // the file shrank while we read it
    got += static_cast<size_t>(n);
  }
  data.resize(got);
  return data;
}

}  // namespace

bool has_gz_extension(std::string_view path) { return ends_with_nocase(path, ".gz"); }

std::string mesh_extension(std::string_view path) {
  if (has_gz_extension(path)) path.remove_suffix(3);
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string_view::npos || (slash != std::string_view::npos && dot < slash)) return "";
  std::string ext(path.substr(dot));
  for (char& c : ext) c = lower(c);
  return ext;
}

std::string gunzip_bytes(const std::string& path, std::string_view gz, size_t limit,
                         const std::string& limit_name) {
  const std::string too_much =
      "decompressed data exceed " +
      (limit_name.empty() ? "the " + size_text(limit) + " limit" : limit_name);
  if (gz.size() < 2 || static_cast<unsigned char>(gz[0]) != 0x1f ||
      static_cast<unsigned char>(gz[1]) != 0x8b)
    throw InputError(path, "not a gzip file");
  z_stream zs{};
  // 16 + MAX_WBITS: expect a gzip header and check its CRC-32 and length trailer.
  if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK) throw InputError(path, "zlib init failed");
  struct End {
    z_stream* z;
    ~End() { inflateEnd(z); }
  } end{&zs};

  // Initial guess: the gzip trailer's ISIZE (size mod 2^32) of the last member,
  // trusted only up to deflate's maximum ratio of 1032:1 (zlib FAQ) so a
  // corrupt or truncated trailer cannot make us allocate gigabytes up front.
  size_t guess = gz.size() * 4;
  if (gz.size() >= 18) {
    const auto* t = reinterpret_cast<const unsigned char*>(gz.data() + gz.size() - 4);
    const size_t isize =
        uint32_t(t[0]) | uint32_t(t[1]) << 8 | uint32_t(t[2]) << 16 | uint32_t(t[3]) << 24;
    guess = std::max(guess, std::min(isize, gz.size() * 1032));
  }
  std::string out(std::min(guess + 1, limit + 1), '\0');
  size_t produced = 0;
  size_t consumed = 0;
  for (;;) {
    if (produced == out.size()) {
      if (out.size() > limit) throw InputError(path, too_much);
      out.resize(std::min(out.size() * 2, limit + 1));
    }
    // zlib counts in uInt; feed at most 1 GiB per call.
    const size_t in_chunk = std::min<size_t>(gz.size() - consumed, size_t{1} << 30);
    const size_t out_chunk = std::min<size_t>(out.size() - produced, size_t{1} << 30);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(gz.data() + consumed));
    zs.avail_in = static_cast<uInt>(in_chunk);
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
    zs.avail_out = static_cast<uInt>(out_chunk);
    const int rc = inflate(&zs, Z_NO_FLUSH);
    consumed += in_chunk - zs.avail_in;
    produced += out_chunk - zs.avail_out;
    if (produced > limit) throw InputError(path, too_much);
    if (rc == Z_STREAM_END) {
      // Another gzip member may follow (as `cat a.gz b.gz` makes); anything
      // else after the stream is corruption.
      if (consumed == gz.size()) break;
      const std::string_view rest = gz.substr(consumed);
      if (rest.size() >= 2 && static_cast<unsigned char>(rest[0]) == 0x1f &&
          static_cast<unsigned char>(rest[1]) == 0x8b) {
        inflateReset(&zs);
        continue;
      }
      throw InputError(path, "corrupt gzip data: trailing garbage after the stream");
    }
    if (rc == Z_BUF_ERROR && consumed == gz.size() && zs.avail_out != 0)
      throw InputError(path, "truncated gzip data");
    if (rc != Z_OK && rc != Z_BUF_ERROR)
      throw InputError(path,
                       std::string("corrupt gzip data: ") + (zs.msg ? zs.msg : "inflate failed"));
    if (consumed == gz.size() && zs.avail_out != 0 && rc == Z_OK) {
      // All input used, output space left, stream not finished: truncated.
      throw InputError(path, "truncated gzip data");
    }
  }
  out.resize(produced);
  return out;
}

std::string read_file_bytes(const std::string& path, size_t limit) {
  if (!has_gz_extension(path)) return read_plain(path, limit);
  // The compressed file itself can not reasonably exceed the output limit.
  const std::string gz = read_plain(path, limit);
  // A decompression bomb stops at kMaxGzipRatio times its own size (with a
  // floor for small files), before it costs gigabytes.
  const size_t bound = std::max(kMinGzipBound, gz.size() * kMaxGzipRatio);
  if (bound < limit)
    return gunzip_bytes(path, gz, bound,
                        std::to_string(kMaxGzipRatio) + " times the compressed size (" +
                            size_text(bound) + "): a decompression bomb?");
  return gunzip_bytes(path, gz, limit);
}

}  // namespace hprt
