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
#include <thread>

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
    signal(SIGHUP, SIG_DFL);
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
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
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

TEST(Interrupt, HangUpStopsAPollingLoopAsTerminateDoes) {
  const int status = in_child([] {
    fiberlab::install_interrupt_handlers();
    raise(SIGHUP);
    if (!fiberlab::interrupt_requested() || fiberlab::interrupt_signal() != SIGHUP) return 11;
    if (std::string(fiberlab::signal_name(SIGHUP)) != "SIGHUP") return 12;
    return 0;
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// A host program's handler (here one counting calls) is replaced only while a
// ScopedInterruptPolling is alive, and put back exactly (same function, same
// flags); a signal in the scope sets the flag, a second one does not end the
// process, and after the scope the host's handler gets signals again.
volatile sig_atomic_t g_host_calls = 0;
extern "C" void host_handler(int) { g_host_calls = g_host_calls + 1; }

TEST(Interrupt, ScopedPollingRestoresTheHostsHandlersExactly) {
  const int status = in_child([] {
    fiberlab::leave_signals_to_host();
    struct sigaction host {};
    host.sa_handler = host_handler;
    sigemptyset(&host.sa_mask);
    host.sa_flags = SA_ONSTACK;
    for (int sig : {SIGINT, SIGTERM}) sigaction(sig, &host, nullptr);
    signal(SIGHUP, SIG_IGN);  // ignored: stays ignored inside the scope
    struct sigaction before {};  // as the system reports the host's (glibc adds SA_RESTORER)
    sigaction(SIGTERM, nullptr, &before);
    {
      fiberlab::ScopedInterruptPolling outer;
      {
        fiberlab::ScopedInterruptPolling inner;  // nested: the outer one restores
        if (outer.received_signal() != 0) return 10;
      }
      struct sigaction now {};
      sigaction(SIGINT, nullptr, &now);
      if (now.sa_handler == host_handler) return 11;  // the inner scope restored too early
      raise(SIGHUP);  // ignored
      if (fiberlab::interrupt_requested()) return 12;
      raise(SIGINT);
      raise(SIGINT);  // a second signal: still running
      if (outer.received_signal() != SIGINT || !fiberlab::interrupt_requested()) return 13;
      if (g_host_calls != 0) return 14;
    }
    for (int sig : {SIGINT, SIGTERM}) {
      struct sigaction now {};
      sigaction(sig, nullptr, &now);
      if (now.sa_handler != host_handler || now.sa_flags != before.sa_flags) return 15;
    }
    struct sigaction hup {};
    sigaction(SIGHUP, nullptr, &hup);
    if (hup.sa_handler != SIG_IGN) return 16;
    if (fiberlab::interrupt_requested()) return 17;  // the next scope starts clear
    raise(SIGINT);
    if (g_host_calls != 1) return 18;
    return 0;
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// In a host program a guarded write installs nothing: the host's handler
// runs (the write then finishes) and no handler of fiberlab stays behind.
TEST(Interrupt, GuardInAHostProgramInstallsNothing) {
  const fs::path tmp = scratch("host_guarded.tmp");
  const int status = in_child([&] {
    fiberlab::leave_signals_to_host();
    struct sigaction host {};
    host.sa_handler = host_handler;
    sigemptyset(&host.sa_mask);
    sigaction(SIGINT, &host, nullptr);
    {
      fiberlab::TempFileGuard guard(tmp.string());
      raise(SIGINT);
      if (g_host_calls != 1) return 10;
    }
    struct sigaction term {};
    sigaction(SIGTERM, nullptr, &term);
    if (term.sa_handler != SIG_DFL) return 11;
    return 0;
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// Whether process `pid` has a handler for `sig` (/proc/PID/status, SigCgt).
bool catches(pid_t pid, int sig) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1;
  return false;
}

// `fiberlab run` stopped by SIGHUP (a closed terminal) saves its checkpoint
// and exits with 128 + SIGHUP, as for SIGTERM and SIGINT; no output, no
// temporary file.
TEST(Interrupt, RunCheckpointsOnHangUp) {
  const fs::path dir = scratch("hup");
  fs::create_directories(dir);
  std::ofstream(dir / "c.yaml") << "photons: 1e10\nsource: {theta_i: [30]}\ntally: {n_theta: 9, n_phi: 12}\n";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    signal(SIGHUP, SIG_DFL);
    const std::string config = (dir / "c.yaml").string(), out = (dir / "out.h5").string();
    execl(FIBERLAB_BINARY, "fiberlab", "run", config.c_str(), "--quiet", "--threads", "1", "-o", out.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // Signal once the run has its handler (a slow start, e.g. under a
  // sanitizer, must not meet SIGHUP's default action instead).
  for (int i = 0; i < 3000 && !catches(pid, SIGHUP); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(pid, SIGHUP);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGHUP);
  EXPECT_TRUE(fs::exists(dir / "out.checkpoint.h5"));
  EXPECT_FALSE(fs::exists(dir / "out.h5"));
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  fs::remove_all(dir);
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
