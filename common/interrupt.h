#pragma once
// SIGINT, SIGTERM and SIGHUP: how fiberlab stops without leaving partial
// output.
//
// In the fiberlab command (process-wide handlers, installed for good):
// - Long loops (the simulation) call install_interrupt_handlers() once and
//   poll interrupt_requested(); they stop cleanly at the next check. A second
//   signal while the first is pending ends the process at once (status
//   128 + signal), so a stuck loop can still be stopped.
// - While a TempFileGuard is alive (around the HDF5 write of a temporary
//   file), a signal unlinks that file and ends the process with status
//   128 + signal: HDF5 calls cannot be interrupted half-way and resumed, and
//   a half-written temporary must not be left behind.
// Without either (handlers never installed and no guard alive), the signals
// keep their default action (the process ends at once). SIGHUP (a closed
// terminal or ssh connection) is treated as SIGTERM.
//
// In a host program that owns its signal dispositions (the Python module:
// Python's own SIGINT handler raises KeyboardInterrupt), after
// leave_signals_to_host() nothing is installed for good:
// - TempFileGuard installs nothing; the host's handlers run as usual (the
//   write finishes, then the host handles the signal).
// - A long loop is wrapped in a ScopedInterruptPolling, which installs the
//   flag-setting handler for its lifetime only and puts back the previous
//   dispositions exactly (sigaction) when the last one ends; the host then
//   re-delivers the signal to its own handler (received_signal()).
//
// The handler only uses async-signal-safe calls (unlink, _exit) on data set
// up before it can run (fixed buffers and sig_atomic_t flags).
#include <string>

namespace fiberlab {

void install_interrupt_handlers();  // SIGINT, SIGTERM, SIGHUP: set a flag (async-signal-safe)
bool interrupt_requested();         // polled by long loops
int interrupt_signal();             // which signal (0 if none)
const char* signal_name(int sig);   // "SIGINT", "SIGTERM", "SIGHUP", else "a signal"

// The host program keeps its own signal handlers: from now on TempFileGuard
// installs no handler (call before any guard; the Python module does at import).
void leave_signals_to_host();

// For a host program (see above): while alive, SIGINT, SIGTERM and SIGHUP
// (those not ignored) set the flag polled by interrupt_requested(); a second
// signal does not end the process. Scopes may nest and overlap (threads):
// the first installs (clearing the flag), the last restores the previous
// sigactions exactly.
class ScopedInterruptPolling {
 public:
  ScopedInterruptPolling();
  ~ScopedInterruptPolling();
  ScopedInterruptPolling(const ScopedInterruptPolling&) = delete;
  ScopedInterruptPolling& operator=(const ScopedInterruptPolling&) = delete;
  // The signal received while this scope was alive (0 if none).
  int received_signal() const;
};

// While alive, a signal also unlinks `path` (async-signal-safe) before the
// process exits with status 128+signal (not after leave_signals_to_host()).
// Up to 8 guards may be alive at once; more throw fiberlab::Error.
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
