// Safe output files: write to a temporary file next to the destination and rename it over the
// destination only once everything has been written.
//
// A failure at any point (an exception, a full disk, a bad input discovered half-way) leaves the
// destination as it was: absent, or the previous file, never a partial file. The temporary file
// is created in the destination's directory (so that the final rename(2) is atomic, on the same
// file system) under the name ".NAME.tmpXXXXXX", and removed again unless committed. Only a
// process killed outright (SIGKILL, a power loss before commit) can leave such a file behind.
//
// The new file gets the permission bits of the file it replaces, or 0666 minus the umask for a
// new file, like a file opened with fopen(). When the destination is a symbolic link, the file it
// points to is replaced and the link kept.
//
// Only a regular file is ever replaced. What the destination is decides the rest:
//   - absent, or a regular file: the temporary file and rename above. A regular file that is
//     read-only (no write permission bit, or not writable by this process) is refused with
//     "... is read-only", like cp(1), even for root (who could otherwise replace it silently);
//   - a character device (/dev/null, a terminal) or a FIFO: written directly, never replaced
//     (renaming over /dev/null as root would destroy it). Opened at the first write or at
//     commit(), so that a probe (constructed, then discarded) does not open a FIFO's reader end;
//   - /dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N: that descriptor, written directly
//     at its current offset (whatever it is: a pipe, a terminal or a file the shell opened);
//   - a directory, a socket, a block device: refused, naming what it is.
// Data written directly cannot be taken back: discard() then only closes the descriptor.
// While a temporary file exists it is registered for removal on SIGINT, SIGTERM and SIGHUP
// (util/signal_cleanup.hpp; the program installs the handlers).
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string_view>

namespace halfback {

class AtomicFile {
 public:
  // Creates the temporary file (for a regular destination). Throws std::system_error ("cannot
  // write 'PATH': REASON") when the directory does not exist or is not writable, or when `target`
  // is a directory, a socket, a block device or a read-only file.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();  // discards the temporary file unless committed

  // Appends to the temporary file. Throws std::system_error (e.g. "No space left on device").
  void write(std::string_view data);

  // Flushes the data to disk and renames the temporary file over the target (closes a direct
  // destination). Throws std::system_error on failure, after removing the temporary file. At
  // most once.
  void commit();

  // Removes the temporary file without touching the target (also done by the destructor).
  void discard() noexcept;

  const std::filesystem::path& target() const noexcept { return target_; }
  const std::filesystem::path& temporary_path() const noexcept { return temp_; }  // "" if direct
  bool committed() const noexcept { return committed_; }
  // Whether the destination is written directly (a device, a FIFO, a standard stream).
  bool direct() const noexcept { return direct_; }

 private:
  void create_temporary(mode_t mode);
  void open_direct();  // at the first write or at commit

  std::filesystem::path target_;    // as given, for messages
  std::filesystem::path resolved_;  // the file that is replaced (symbolic links followed)
  std::filesystem::path temp_;
  int fd_ = -1;
  int stream_fd_ = -1;  // direct: the descriptor named by /dev/stdout, /dev/fd/N, ...
  int temp_slot_ = -1;  // the temporary's slot in the signal-cleanup registry
  bool direct_ = false;
  bool finished_ = false;  // committed or discarded
  bool committed_ = false;
};

// Writes `contents` to `target` atomically (AtomicFile, write, commit).
void write_file_atomically(const std::filesystem::path& target, std::string_view contents);

}  // namespace halfback
