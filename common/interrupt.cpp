#include "common/interrupt.h"

#include <fmt/core.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>

#include "common/error.h"

namespace fiberlab {

namespace {

constexpr int kSlots = 8;
constexpr std::size_t kPathBytes = 4096;

// One temporary file to unlink on a signal. `armed` is set only after the
// path is complete and cleared before the path is reused, so the handler
// never reads a half-written path.
struct Slot {
  std::atomic<int> armed{0};
  char path[kPathBytes] = {};
};

Slot g_slots[kSlots];
std::mutex g_slots_mutex;  // guards claiming/releasing slots (never taken in the handler)
std::atomic<bool> g_slot_used[kSlots];

volatile std::sig_atomic_t g_signal = 0;          // the first signal received
volatile std::sig_atomic_t g_polling = 0;         // install_interrupt_handlers() was called
std::atomic<int> g_guards_alive{0};
std::once_flag g_installed;
std::atomic<bool> g_host_owns_signals{false};     // leave_signals_to_host() was called

// The signals that stop fiberlab: interrupt, terminate, and a hang-up (a
// closed terminal or ssh connection), which the command treats as SIGTERM.
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kSignalCount = sizeof(kSignals) / sizeof(kSignals[0]);

// ScopedInterruptPolling: how many scopes are alive, and the dispositions
// the first one replaced (put back by the last).
std::mutex g_scope_mutex;
int g_scopes = 0;
struct sigaction g_previous[kSignalCount];
bool g_replaced[kSignalCount] = {};

static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

void unlink_guarded_files() {
  for (Slot& s : g_slots)
    if (s.armed.load(std::memory_order_acquire)) unlink(s.path);
}

extern "C" void on_interrupt(int sig) {
  const bool first = g_signal == 0;
  if (first) g_signal = sig;
  const bool guarded = g_guards_alive.load(std::memory_order_acquire) > 0;
  if (guarded) unlink_guarded_files();
  // Keep running only when a loop polls for the flag and this is the first
  // signal, and no temporary file is being written.
  if (g_polling && first && !guarded) return;
  _exit(128 + sig);
}

// In a host program: record the first signal, nothing else (the host's own
// handler gets it once the scope has put it back).
extern "C" void on_interrupt_in_host(int sig) {
  if (g_signal == 0) g_signal = sig;
}

bool ignored(const struct sigaction& sa) {
  return !(sa.sa_flags & SA_SIGINFO) && sa.sa_handler == SIG_IGN;
}

void install_handlers_once() {
  std::call_once(g_installed, [] {
    struct sigaction sa {};
    sa.sa_handler = on_interrupt;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    for (int sig : kSignals) {
      struct sigaction old {};
      sigaction(sig, nullptr, &old);
      // A signal ignored by the parent (e.g. a background job of a
      // non-interactive shell) stays ignored, as the shell intended.
      if (ignored(old)) continue;
      sigaction(sig, &sa, nullptr);
    }
  });
}

}  // namespace

void install_interrupt_handlers() {
  g_polling = 1;
  install_handlers_once();
}

bool interrupt_requested() { return g_signal != 0; }

int interrupt_signal() { return static_cast<int>(g_signal); }

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

void leave_signals_to_host() { g_host_owns_signals = true; }

ScopedInterruptPolling::ScopedInterruptPolling() {
  std::lock_guard<std::mutex> lock(g_scope_mutex);
  if (g_scopes++ > 0) return;
  g_signal = 0;
  struct sigaction sa {};
  sa.sa_handler = on_interrupt_in_host;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (int i = 0; i < kSignalCount; ++i) {
    sigaction(kSignals[i], nullptr, &g_previous[i]);
    // An ignored signal stays ignored, as whoever ignored it intended.
    g_replaced[i] = !ignored(g_previous[i]);
    if (g_replaced[i]) sigaction(kSignals[i], &sa, nullptr);
  }
}

ScopedInterruptPolling::~ScopedInterruptPolling() {
  std::lock_guard<std::mutex> lock(g_scope_mutex);
  if (--g_scopes > 0) return;
  for (int i = 0; i < kSignalCount; ++i)
    if (g_replaced[i]) sigaction(kSignals[i], &g_previous[i], nullptr);
  g_signal = 0;  // received_signal() was read before; the next scope starts clear
}

int ScopedInterruptPolling::received_signal() const { return static_cast<int>(g_signal); }

TempFileGuard::TempFileGuard(std::string path) {
  if (path.size() + 1 > kPathBytes)
    throw Error(fmt::format("{}: temporary file path is longer than {} bytes", path, kPathBytes - 1));
  if (!g_host_owns_signals) install_handlers_once();
  std::lock_guard<std::mutex> lock(g_slots_mutex);
  for (int i = 0; i < kSlots; ++i) {
    if (g_slot_used[i].load()) continue;
    g_slot_used[i] = true;
    Slot& s = g_slots[i];
    std::memcpy(s.path, path.c_str(), path.size() + 1);
    s.armed.store(1, std::memory_order_release);
    g_guards_alive.fetch_add(1, std::memory_order_acq_rel);
    slot_ = i;
    return;
  }
  throw Error(fmt::format("{}: more than {} temporary files written at once", path, kSlots));
}

TempFileGuard::~TempFileGuard() {
  if (slot_ < 0) return;
  std::lock_guard<std::mutex> lock(g_slots_mutex);
  g_slots[slot_].armed.store(0, std::memory_order_release);
  g_guards_alive.fetch_sub(1, std::memory_order_acq_rel);
  g_slot_used[slot_] = false;
}

}  // namespace fiberlab
