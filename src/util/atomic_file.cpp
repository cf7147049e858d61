#include "halfback/util/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "halfback/util/signal_cleanup.hpp"

namespace halfback {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(int err, const fs::path& target) {
  std::string what = "cannot write '" + target.string() + "'";
  if (err == EFBIG) what += " (above the file size limit of this process, ulimit -f)";
  if (err == ENOSPC) what += " (the file system is full)";
  throw std::system_error(err, std::generic_category(), what);
}

// The process's umask, read without changing it (umask(2) can only be read by setting it, which
// races with other threads creating files).
mode_t current_umask() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Umask:", 0) == 0) {
      try {
        return static_cast<mode_t>(std::stoul(line.substr(6), nullptr, 8) & 0777);
      } catch (...) {
        break;
      }
    }
  }
  return 022;
}

// The descriptor a path names by itself (/dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N),
// or -1. Such a path is a link to whatever the descriptor is open on, which may be a pipe (no
// file to rename over) or a file the shell opened at some offset (which a rename would lose).
int standard_stream_fd(const fs::path& path) {
  const std::string& p = path.native();
  if (p == "/dev/stdout") return 1;
  if (p == "/dev/stderr") return 2;
  for (const std::string_view prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    if (!p.starts_with(prefix)) continue;
    int fd = -1;
    const char* first = p.data() + prefix.size();
    const auto [end, ec] = std::from_chars(first, p.data() + p.size(), fd);
    if (ec == std::errc() && end == p.data() + p.size() && end != first) return fd;
  }
  return -1;
}

std::string text_with_mode(const char* text, mode_t mode) {
  char digits[8];
  std::snprintf(digits, sizeof digits, "%04o", unsigned(mode & 07777));
  return text + std::string(digits);
}

const char* file_type_name(mode_t mode) {
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}

[[noreturn]] void refuse(int err, const fs::path& target, const std::string& why) {
  throw std::system_error(err, std::generic_category(),
                          "cannot write '" + target.string() + "' (" + why + ")");
}

// Whether an existing destination is written directly (a device or FIFO), not replaced (a
// regular file); anything else is refused (throws).
bool is_direct_destination(const struct stat& st, const fs::path& resolved,
                           const fs::path& target) {
  if (S_ISDIR(st.st_mode)) fail(EISDIR, target);
  if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) {
    if (::access(resolved.c_str(), W_OK) != 0) fail(errno, target);
    return true;
  }
  if (!S_ISREG(st.st_mode))
    refuse(ENOTSUP, target,
           std::string("it is ") + file_type_name(st.st_mode) +
               "; only regular files, character devices and FIFOs are written");
  // Read-only: no write bit at all (root included, like cp), or not writable by this process.
  if ((st.st_mode & 0222) == 0 || (::access(resolved.c_str(), W_OK) != 0 && errno == EACCES))
    refuse(
        EACCES, target,
        text_with_mode("it is read-only, mode ", st.st_mode) + "; make it writable or remove it");
  return false;
}

}  // namespace

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  if (target_.empty()) fail(ENOENT, target_);
  if (const int fd = standard_stream_fd(target_); fd >= 0) {
    direct_ = true;
    stream_fd_ = fd;
    return;
  }
  std::error_code ec;
  resolved_ = target_;
  // Follow a symbolic link to the file it names (a dangling link: the file it would create).
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(resolved_, ec)); ++hops) {
    const fs::path to = fs::read_symlink(resolved_, ec);
    if (ec) fail(ec.value(), target_);
    resolved_ = to.is_absolute() ? to : resolved_.parent_path() / to;
  }
  // Still a link after 40: a loop (or a chain longer than the system follows). Renaming onto it
  // would replace a link of the loop with a regular file: refuse, as open(2) would (ELOOP).
  if (fs::is_symlink(fs::symlink_status(resolved_, ec))) fail(ELOOP, target_);
  struct stat st {};
  const bool exists = ::stat(resolved_.c_str(), &st) == 0;
  if (exists && is_direct_destination(st, resolved_, target_)) {
    direct_ = true;
    return;
  }
  create_temporary(exists ? st.st_mode & 07777 : 0666 & ~current_umask());
}

void AtomicFile::create_temporary(mode_t mode) {
  const fs::path dir = resolved_.has_parent_path() ? resolved_.parent_path() : fs::path(".");
  std::string name(".");  // (built in steps: GCC 12 warns wrongly on "." + string)
  name += resolved_.filename().string();
  name += ".tmpXXXXXX";
  const std::string pattern = (dir / name).string();
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  {
    const CleanupSignalsBlocked blocked;  // no signal between creating and registering the file
    fd_ = ::mkostemp(buf.data(), O_CLOEXEC);
    if (fd_ < 0) fail(errno, target_);
    temp_ = fs::path(buf.data());
    temp_slot_ = register_temporary(temp_);
  }
  if (::fchmod(fd_, mode) != 0) {
    const int err = errno;
    discard();
    fail(err, target_);
  }
}

AtomicFile::~AtomicFile() {
  discard();
}

void AtomicFile::open_direct() {
  fd_ = stream_fd_ >= 0 ? ::fcntl(stream_fd_, F_DUPFD_CLOEXEC, 0)
                        : ::open(resolved_.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
  if (fd_ < 0) fail(errno, target_);
}

void AtomicFile::write(std::string_view data) {
  if (finished_) fail(EBADF, target_);
  if (direct_ && fd_ < 0) open_direct();
  while (!data.empty()) {
    const ssize_t n = ::write(fd_, data.data(), data.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(errno, target_);
    }
    data.remove_prefix(static_cast<std::size_t>(n));
  }
}

void AtomicFile::commit() {
  if (finished_) fail(EBADF, target_);
  if (direct_ && fd_ < 0) open_direct();
  int err = 0;
  // fsync: EINVAL for pipes, devices and some file systems, EROFS on read-only ones.
  if (!direct_ && ::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS) err = errno;
  if (::close(fd_) != 0 && err == 0 && errno != EINTR) err = errno;
  fd_ = -1;
  if (err == 0 && !direct_ && std::rename(temp_.c_str(), resolved_.c_str()) != 0) err = errno;
  if (err != 0) {
    discard();
    fail(err, target_);
  }
  unregister_temporary(temp_slot_);
  temp_slot_ = -1;
  finished_ = committed_ = true;
}

void AtomicFile::discard() noexcept {
  finished_ = true;
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!committed_ && !temp_.empty()) {
    ::unlink(temp_.c_str());
    temp_.clear();
  }
  unregister_temporary(temp_slot_);
  temp_slot_ = -1;
}

void write_file_atomically(const fs::path& target, std::string_view contents) {
  AtomicFile file(target);
  file.write(contents);
  file.commit();
}

}  // namespace halfback
