// Reads a whole input file into memory, gunzipping it transparently when the
// name ends in ".gz" (zlib, concatenated members allowed). Sizes are capped so
// a hostile file or a decompression bomb is an InputError, never an OOM.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace hprt {

// Largest file (after decompression) we accept: 4 GiB, far above meshes of
// tens of millions of triangles (a 20M-triangle binary PLY is ~0.4 GB).
inline constexpr size_t kMaxInputBytes = size_t{4} << 30;

// A .gz file may decompress to at most kMaxGzipRatio times its own size, or
// kMinGzipBound, whichever is more (real meshes compress 3-5 times; a run of
// zeros about 1000 times).
inline constexpr size_t kMaxGzipRatio = 100;
inline constexpr size_t kMinGzipBound = size_t{64} << 20;

// True when `path` ends in ".gz" (any case).
bool has_gz_extension(std::string_view path);

// Lower-case extension of `path` after dropping a trailing ".gz": "x.PLY.gz" -> ".ply".
std::string mesh_extension(std::string_view path);

// The file's bytes (decompressed for .gz). Throws InputError(path, ...) when
// the file cannot be opened or read or is not a regular file (a FIFO or a
// device), the gzip stream is corrupt or truncated, or the data exceed
// `limit` bytes (or kMaxGzipRatio times the .gz file's size).
std::string read_file_bytes(const std::string& path, size_t limit = kMaxInputBytes);

// Decompresses a gzip stream held in memory (used by read_file_bytes; exposed
// for tests). `path` only names the data in error messages, `limit_name` the
// limit ("the N MiB limit" when empty).
std::string gunzip_bytes(const std::string& path, std::string_view gz, size_t limit,
                         const std::string& limit_name = {});

}  // namespace hprt
