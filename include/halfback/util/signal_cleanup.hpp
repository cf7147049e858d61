// Temporary files removed when the process is interrupted: a process-wide registry of the paths
// of live temporary files (AtomicFile registers each of its temporaries), and handlers for
// SIGINT, SIGTERM and SIGHUP that unlink every registered path and then die of the same signal,
// with its default action (so the parent still sees "killed by SIGTERM", not an exit code).
//
// The handler only calls unlink(2), signal(2) and raise(3), which are async-signal-safe, over a
// fixed-size table of fixed-size paths that registration fills without allocating in the
// handler. A path that does not fit (more than kMaxTemporaries live at once, or longer than
// kMaxTemporaryPath) is not registered: the file is then removed as usual on success and on
// errors, but not on a signal. SIGKILL cannot be caught: a process killed by it (or by a power
// loss) can leave ".NAME.tmpXXXXXX" files beside its outputs (docs/cli.md).
#pragma once

#include <signal.h>

#include <cstddef>
#include <filesystem>

namespace halfback {

inline constexpr std::size_t kMaxTemporaries = 64;
inline constexpr std::size_t kMaxTemporaryPath = 4096;  // bytes, with the terminating NUL

// Installs the handlers for SIGINT, SIGTERM and SIGHUP (once; later calls do nothing). A signal
// that is ignored when this is called (e.g. SIGHUP under nohup) stays ignored. Programs call it
// at the start of main(); a library never installs handlers by itself.
void install_temporary_cleanup_handlers();

// Registers a temporary file (made absolute, so that a later chdir does not matter). Returns a
// slot to unregister, or -1 when the table is full or the path too long (see above).
// Ignores SIGXFSZ, so that a write beyond the file size limit (ulimit -f, RLIMIT_FSIZE) fails
// with EFBIG, which AtomicFile reports as an error ("File too large") after removing its
// temporary, instead of killing the process with no message and the temporary left behind.
// Programs call it at the start of main() (Python's interpreter ignores SIGXFSZ itself).
void ignore_file_size_signal();

int register_temporary(const std::filesystem::path& path) noexcept;

// Forgets a slot returned by register_temporary (-1 is ignored). Call it after the file has been
// renamed or removed: a signal in between unlinks a path that no longer exists, which is harmless.
void unregister_temporary(int slot) noexcept;

// Blocks SIGINT, SIGTERM and SIGHUP on the calling thread while it lives. Create a temporary file
// and register it inside one, so that a signal cannot come between the two: a signal that arrives
// meanwhile is handled when the block ends, once the file is registered. (The kernel may still
// hand a signal sent to the process to another thread that does not block it, in that window.)
class CleanupSignalsBlocked {
 public:
  CleanupSignalsBlocked() noexcept;
  ~CleanupSignalsBlocked();
  CleanupSignalsBlocked(const CleanupSignalsBlocked&) = delete;
  CleanupSignalsBlocked& operator=(const CleanupSignalsBlocked&) = delete;

 private:
  sigset_t previous_;
};

// The number of registered temporaries (for tests).
std::size_t registered_temporaries() noexcept;

}  // namespace halfback
