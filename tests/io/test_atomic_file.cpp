#include "io/files/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"

namespace fs = std::filesystem;

TEST(AtomicFile, CommitRenamesAndLeavesNoTemporary) {
  const fs::path dir = fs::temp_directory_path() / "hprt_atomic_test";
  fs::create_directories(dir);
  const std::string target = (dir / "out.bin").string();
  fs::remove(target);
  const char data[] = "hello";
  hprt::write_file_atomic(target, data, 5);
  EXPECT_EQ(fs::file_size(target), 5u);
  for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename(), "out.bin");
  fs::remove_all(dir);
}

TEST(AtomicFile, UncommittedLeavesNothing) {
  const fs::path dir = fs::temp_directory_path() / "hprt_atomic_test2";
  fs::create_directories(dir);
  {
    hprt::AtomicFile f((dir / "x.png").string());
    std::ofstream(f.temp_path()) << "partial";
  }
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingDirectoryIsInputError) {
  EXPECT_THROW(hprt::AtomicFile("/nonexistent_dir_hprt/out.hits"), hprt::InputError);
}
