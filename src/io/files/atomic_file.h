// Output files appear whole or not at all: data is written to a temporary
// name beside the target and renamed at commit(). An uncommitted file is
// removed by the destructor and, on SIGINT/SIGTERM, by the signal handler.
#pragma once

#include <string>

namespace hprt {

class AtomicFile {
 public:
  // Throws InputError naming `path` when its directory does not exist or is
  // not writable (checked by creating the temporary file).
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& path() const { return path_; }
  void commit();  // rename temp -> path; throws InputError on failure

 private:
  std::string path_;
  std::string temp_;
  bool committed_ = false;
};

// Writes `size` bytes atomically to `path`.
void write_file_atomic(const std::string& path, const void* data, size_t size);

// Installs SIGINT/SIGTERM handlers that remove every uncommitted temporary
// file, then re-raise the signal. Called once by the CLI.
void install_output_cleanup_handlers();

}  // namespace hprt
