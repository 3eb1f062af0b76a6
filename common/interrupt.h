#pragma once
// SIGINT and SIGTERM: how fiberlab stops without leaving partial output.
//
// Two uses:
// - Long loops (the simulation) call install_interrupt_handlers() once and
//   poll interrupt_requested(); they stop cleanly at the next check. A second
//   signal while the first is pending ends the process at once (status
//   128 + signal), so a stuck loop can still be stopped.
// - While a TempFileGuard is alive (around the HDF5 write of a temporary
//   file), a signal unlinks that file and ends the process with status
//   128 + signal: HDF5 calls cannot be interrupted half-way and resumed, and
//   a half-written temporary must not be left behind.
// Without either (handlers never installed and no guard alive), SIGINT and
// SIGTERM keep their default action (the process ends at once).
//
// The handler only uses async-signal-safe calls (unlink, _exit) on data set
// up before it can run (fixed buffers and sig_atomic_t flags).
#include <string>

namespace fiberlab {

void install_interrupt_handlers();  // SIGINT, SIGTERM: set a flag (async-signal-safe)
bool interrupt_requested();         // polled by long loops
int interrupt_signal();             // which signal (0 if none)

// While alive, a signal also unlinks `path` (async-signal-safe) before the
// process exits with status 128+signal. Up to 8 guards may be alive at once;
// more throw fiberlab::Error.
class TempFileGuard {
 public:
  explicit TempFileGuard(std::string path);
  ~TempFileGuard();
  TempFileGuard(const TempFileGuard&) = delete;
  TempFileGuard& operator=(const TempFileGuard&) = delete;

 private:
  int slot_ = -1;
};

}  // namespace fiberlab
