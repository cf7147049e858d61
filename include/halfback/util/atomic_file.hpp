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
#pragma once

#include <filesystem>
#include <string_view>

namespace halfback {

class AtomicFile {
 public:
  // Creates the temporary file. Throws std::system_error ("cannot write 'PATH': REASON") when the
  // directory does not exist or is not writable, or when `target` is a directory.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();  // discards the temporary file unless committed

  // Appends to the temporary file. Throws std::system_error (e.g. "No space left on device").
  void write(std::string_view data);

  // Flushes the data to disk and renames the temporary file over the target. Throws
  // std::system_error on failure, after removing the temporary file. At most once.
  void commit();

  // Removes the temporary file without touching the target (also done by the destructor).
  void discard() noexcept;

  const std::filesystem::path& target() const noexcept { return target_; }
  const std::filesystem::path& temporary_path() const noexcept { return temp_; }
  bool committed() const noexcept { return committed_; }

 private:
  std::filesystem::path target_;    // as given, for messages
  std::filesystem::path resolved_;  // the file that is replaced (symbolic links followed)
  std::filesystem::path temp_;
  int fd_ = -1;
  bool committed_ = false;
};

// Writes `contents` to `target` atomically (AtomicFile, write, commit).
void write_file_atomically(const std::filesystem::path& target, std::string_view contents);

}  // namespace halfback
