#include "halfback/util/signal_cleanup.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "halfback/util/atomic_file.hpp"

namespace halfback {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::path(testing::TempDir()) / ("signal_cleanup_test_" + std::to_string(getpid()) + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool has_temporary(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp") != std::string::npos) return true;
  return false;
}

TEST(SignalCleanup, AtomicFileRegistersItsTemporaryWhileItExists) {
  const fs::path dir = fresh_dir("registers");
  const std::size_t before = registered_temporaries();
  {
    AtomicFile f(dir / "out.txt");
    EXPECT_EQ(registered_temporaries(), before + 1);
    f.commit();
    EXPECT_EQ(registered_temporaries(), before);
  }
  {
    AtomicFile f(dir / "other.txt");
    EXPECT_EQ(registered_temporaries(), before + 1);
  }
  EXPECT_EQ(registered_temporaries(), before);
  fs::remove_all(dir);
}

TEST(SignalCleanup, FullTableIsReportedNotOverrun) {
  int slots[kMaxTemporaries + 1];
  std::size_t taken = 0;
  for (int& s : slots) {
    s = register_temporary("/nonexistent/halfback-test");
    taken += s >= 0;
  }
  EXPECT_EQ(slots[kMaxTemporaries], -1);
  EXPECT_LE(taken, kMaxTemporaries);
  for (int s : slots) unregister_temporary(s);
  EXPECT_EQ(register_temporary(std::string(kMaxTemporaryPath, 'x')), -1);
}

// A child process with the handlers installed and a temporary file open dies of each signal:
// the temporary is gone, and its parent sees the signal (not an exit code).
TEST(SignalCleanup, SignalRemovesTheTemporaryAndKillsWithTheSignal) {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    const fs::path dir = fresh_dir("sig" + std::to_string(sig));
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      ::close(ready[0]);
      // A shell's background job inherits SIGINT ignored, and the handlers rightly keep an
      // ignored signal ignored: start from the default so that the test means the same anywhere.
      ::signal(sig, SIG_DFL);
      install_temporary_cleanup_handlers();
      AtomicFile f(dir / "out.bin");
      f.write("partial");
      (void)!::write(ready[1], "r", 1);
      for (;;) ::pause();
    }
    ::close(ready[1]);
    char c = 0;
    ASSERT_EQ(::read(ready[0], &c, 1), 1);
    ::close(ready[0]);
    EXPECT_TRUE(has_temporary(dir));
    ::kill(pid, sig);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status;
    EXPECT_FALSE(has_temporary(dir)) << "signal " << sig;
    EXPECT_TRUE(fs::is_empty(dir));
    fs::remove_all(dir);
  }
}

}  // namespace
}  // namespace halfback
