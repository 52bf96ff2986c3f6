// Interrupting `hprt render` (SIGINT, SIGTERM) once it has started: the
// process dies of that signal and leaves no output file and no temporary
// file in the output directory.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/cli_test_support.h"

extern char** environ;

namespace fs = std::filesystem;

namespace hprt {
namespace {

class Signal : public test::TempDirTest {
 protected:
  Signal() : TempDirTest("hprt_signal_") {}

  // Starts `hprt render` at 8192x4096 (hundreds of millions of rays: far
  // longer than the wait below), sends `sig` once it has run for a second,
  // and returns the wait status.
  int render_and_interrupt(int sig, const std::string& output_name) {
    const std::string scene = std::string(HPRT_SOURCE_DIR) + "/data/scenes/default.json";
    const std::string out = (dir_ / output_name).string();
    const std::string log = (dir_ / "stderr.txt").string();
    std::vector<std::string> args = {HPRT_BINARY, "render",    scene, "--width", "8192", "--height",
                                     "4096",      "--threads", "2",   "-o",      out};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT, 0644);
    // The child must not inherit an ignored SIGINT (e.g. from a background shell).
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, HPRT_BINARY, &fa, &attr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&attr);
    EXPECT_EQ(rc, 0) << "cannot start " << HPRT_BINARY;
    if (rc != 0) return -1;

    // Loading and building take well under a second; then it renders.
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    int status = 0;
    EXPECT_EQ(waitpid(pid, &status, WNOHANG), 0)
        << "hprt render ended before the signal (status " << status << ")";
    ::kill(pid, sig);
    // It must die promptly; kill it hard after 30 s so the test cannot hang.
    for (int i = 0; i < 300; ++i) {
      if (waitpid(pid, &status, WNOHANG) == pid) return status;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ::kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    ADD_FAILURE() << "hprt render did not stop within 30 s of signal " << sig;
    return status;
  }

  // Every file in the directory except the captured stderr.
  std::vector<std::string> leftovers() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename() != "stderr.txt") names.push_back(e.path().filename().string());
    return names;
  }
};

TEST_F(Signal, SigintDuringRenderLeavesNoFile) {
  const int status = render_and_interrupt(SIGINT, "big.png");
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_EQ(leftovers(), std::vector<std::string>{});
}

TEST_F(Signal, SigtermDuringExrRenderLeavesNoFile) {
  const int status = render_and_interrupt(SIGTERM, "big.exr");
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_EQ(leftovers(), std::vector<std::string>{});
}

}  // namespace
}  // namespace hprt
