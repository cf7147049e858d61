// A FIFO read on a thread, for the tests of outputs that are FIFOs (util and CLI tests).
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <thread>

namespace halfback::test {

// Reads a FIFO on a thread. It holds a writer end of its own, so that it neither blocks when the
// tool never opens the FIFO (e.g. replaced it by a file) nor sees an early end of file:
// finish() closes that writer and returns what came through.
class FifoReader {
 public:
  explicit FifoReader(const std::filesystem::path& fifo)
      : read_(::open(fifo.c_str(), O_RDONLY | O_NONBLOCK)), write_(::open(fifo.c_str(), O_WRONLY)) {
    ::fcntl(read_, F_SETFL, 0);  // blocking reads from now on
    thread_ = std::thread([this] {
      char buf[1 << 16];
      ssize_t n = 0;
      while ((n = ::read(read_, buf, sizeof buf)) > 0) data_.append(buf, std::size_t(n));
    });
  }
  FifoReader(const FifoReader&) = delete;
  FifoReader& operator=(const FifoReader&) = delete;
  ~FifoReader() {
    if (thread_.joinable()) finish();
  }
  std::string finish() {
    ::close(write_);
    thread_.join();
    ::close(read_);
    return data_;
  }

 private:
  int read_, write_;
  std::thread thread_;
  std::string data_;
};

}  // namespace halfback::test
