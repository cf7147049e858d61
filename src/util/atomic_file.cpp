#include "halfback/util/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

namespace halfback {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(int err, const fs::path& target) {
  throw std::system_error(err, std::generic_category(), "cannot write '" + target.string() + "'");
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

}  // namespace

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  if (target_.empty()) fail(ENOENT, target_);
  std::error_code ec;
  resolved_ = target_;
  // Follow a symbolic link to the file it names (a dangling link: the file it would create).
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(resolved_, ec)); ++hops) {
    const fs::path to = fs::read_symlink(resolved_, ec);
    if (ec) fail(ec.value(), target_);
    resolved_ = to.is_absolute() ? to : resolved_.parent_path() / to;
  }
  const fs::file_status st = fs::status(resolved_, ec);
  if (fs::is_directory(st)) fail(EISDIR, target_);

  const fs::path dir = resolved_.has_parent_path() ? resolved_.parent_path() : fs::path(".");
  std::string name(".");  // (built in steps: GCC 12 warns wrongly on "." + string)
  name += resolved_.filename().string();
  name += ".tmpXXXXXX";
  const std::string pattern = (dir / name).string();
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  fd_ = ::mkostemp(buf.data(), O_CLOEXEC);
  if (fd_ < 0) fail(errno, target_);
  temp_ = fs::path(buf.data());

  const mode_t mode = fs::exists(st) ? static_cast<mode_t>(st.permissions() & fs::perms::mask)
                                     : static_cast<mode_t>(0666 & ~current_umask());
  if (::fchmod(fd_, mode) != 0) {
    const int err = errno;
    discard();
    fail(err, target_);
  }
}

AtomicFile::~AtomicFile() {
  discard();
}

void AtomicFile::write(std::string_view data) {
  if (fd_ < 0) fail(EBADF, target_);
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
  if (fd_ < 0) fail(EBADF, target_);
  int err = 0;
  if (::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS) err = errno;  // EINVAL: pipes, ...
  if (::close(fd_) != 0 && err == 0 && errno != EINTR) err = errno;
  fd_ = -1;
  if (err == 0 && std::rename(temp_.c_str(), resolved_.c_str()) != 0) err = errno;
  if (err != 0) {
    discard();
    fail(err, target_);
  }
  committed_ = true;
}

void AtomicFile::discard() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!committed_ && !temp_.empty()) {
    ::unlink(temp_.c_str());
    temp_.clear();
  }
}

void write_file_atomically(const fs::path& target, std::string_view contents) {
  AtomicFile file(target);
  file.write(contents);
  file.commit();
}

}  // namespace halfback
