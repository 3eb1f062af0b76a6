// common/interrupt.h: a signal during a guarded write removes the temporary
// file and ends the process with 128 + signal; a polling loop sees the flag
// and goes on; AtomicOutput leaves no temporary on any way out. Each case runs
// in a forked child (the handlers are process-wide state).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/interrupt.h"

namespace {

namespace fs = std::filesystem;

// Runs `body` in a child with SIGINT/SIGTERM at their default action (ctest
// may start us with SIGINT ignored); returns the child's wait status.
int in_child(const std::function<int()>& body) {
  const pid_t pid = fork();
  if (pid == 0) {
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    _exit(body());
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("fiberlab_interrupt_" + std::to_string(getpid()));
  fs::create_directories(d);
  return d / name;
}

TEST(Interrupt, SignalDuringGuardedWriteRemovesTheTemporaryFile) {
  for (int sig : {SIGINT, SIGTERM}) {
    const fs::path tmp = scratch("guarded.tmp");
    const int status = in_child([&] {
      fiberlab::TempFileGuard guard(tmp.string());
      std::ofstream(tmp) << "half-written";
      raise(sig);
      return 0;  // not reached
    });
    ASSERT_TRUE(WIFEXITED(status)) << "signal " << sig;
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    EXPECT_FALSE(fs::exists(tmp)) << "temporary left after signal " << sig;
  }
}

TEST(Interrupt, PollingLoopSeesTheFlagAndASecondSignalEnds) {
  const int status = in_child([] {
    fiberlab::install_interrupt_handlers();
    if (fiberlab::interrupt_requested() || fiberlab::interrupt_signal() != 0) return 10;
    raise(SIGTERM);
    if (!fiberlab::interrupt_requested() || fiberlab::interrupt_signal() != SIGTERM) return 11;
    raise(SIGINT);  // a second signal: ends at once
    return 12;
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGINT);
}

TEST(Interrupt, AtomicOutputLeavesNoTemporaryOnSignalOrException) {
  const fs::path target = scratch("out.h5");
  fs::remove(target);
  // Signal while the temporary is being written.
  const int status = in_child([&] {
    fiberlab::AtomicOutput out(target.string());
    std::ofstream(out.temp_path()) << "partial";
    raise(SIGINT);
    return 0;
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGINT);
  // Exception before commit.
  try {
    fiberlab::AtomicOutput out(target.string());
    std::ofstream(out.temp_path()) << "partial";
    throw fiberlab::Error("disk full");
  } catch (const fiberlab::Error&) {
  }
  for (const auto& e : fs::directory_iterator(target.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  EXPECT_FALSE(fs::exists(target));
  // A stale temporary of a process that no longer exists is removed by the next write.
  const pid_t dead = fork();
  if (dead == 0) _exit(0);
  waitpid(dead, nullptr, 0);
  const fs::path stale = target.parent_path() / (".out.h5.tmp-" + std::to_string(dead));
  std::ofstream(stale) << "crashed";
  {
    fiberlab::AtomicOutput out(target.string());
    std::ofstream(out.temp_path()) << "complete";
    out.commit();
  }
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(target));
  fs::remove_all(target.parent_path());
}

}  // namespace
