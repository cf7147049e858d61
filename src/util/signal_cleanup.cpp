#include "halfback/util/signal_cleanup.hpp"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <system_error>

namespace halfback {

namespace {

// A slot is free, being filled (not yet visible to the handler), or live.
enum SlotState : int { kFree = 0, kFilling = 1, kLive = 2 };

struct Slot {
  std::atomic<int> state{kFree};
  char path[kMaxTemporaryPath] = {};
};

static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the slot states");

std::array<Slot, kMaxTemporaries> g_slots;

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void remove_temporaries_and_die(int sig) {
  for (Slot& slot : g_slots)
    if (slot.state.load(std::memory_order_acquire) == kLive) ::unlink(slot.path);
  // Die of the same signal: the default action once the handler returns (the signal is blocked
  // while its handler runs, so raise() only makes it pending).
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

void install_temporary_cleanup_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int sig : kCleanupSignals) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
      struct sigaction action {};
      action.sa_handler = remove_temporaries_and_die;
      sigemptyset(&action.sa_mask);
      for (const int other : kCleanupSignals) sigaddset(&action.sa_mask, other);
      ::sigaction(sig, &action, nullptr);
    }
  });
}

void ignore_file_size_signal() {
  ::signal(SIGXFSZ, SIG_IGN);
}

int register_temporary(const std::filesystem::path& path) noexcept {
  std::string text;
  try {
    std::error_code ec;
    text = std::filesystem::absolute(path, ec).native();
    if (ec) return -1;
  } catch (...) {  // out of memory: the file is then only removed the ordinary way
    return -1;
  }
  if (text.size() + 1 > kMaxTemporaryPath) return -1;
  for (std::size_t i = 0; i < g_slots.size(); ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kFilling, std::memory_order_acquire))
      continue;
    std::memcpy(g_slots[i].path, text.c_str(), text.size() + 1);
    g_slots[i].state.store(kLive, std::memory_order_release);
    return int(i);
  }
  return -1;
}

void unregister_temporary(int slot) noexcept {
  if (slot < 0 || std::size_t(slot) >= g_slots.size()) return;
  g_slots[std::size_t(slot)].state.store(kFree, std::memory_order_release);
}

CleanupSignalsBlocked::CleanupSignalsBlocked() noexcept {
  sigset_t block;
  sigemptyset(&block);
  for (const int sig : kCleanupSignals) sigaddset(&block, sig);
  ::pthread_sigmask(SIG_BLOCK, &block, &previous_);
}

CleanupSignalsBlocked::~CleanupSignalsBlocked() {
  ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
}

std::size_t registered_temporaries() noexcept {
  std::size_t n = 0;
  for (const Slot& slot : g_slots) n += slot.state.load(std::memory_order_acquire) == kLive;
  return n;
}

}  // namespace halfback
