// A minimal parallel loop for the BRDF code: [0, n) is cut into one contiguous block per thread.
// Small ranges run on the calling thread. The first exception thrown by a block is rethrown on the
// calling thread after all blocks have finished.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace halfback::detail {

// f(begin, end) over blocks of at least `grain` items.
template <class F>
void parallel_for(std::size_t n, std::size_t grain, F&& f) {
  const std::size_t hw = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t blocks = std::min(hw, n / std::max<std::size_t>(grain, 1));
  if (blocks <= 1) {
    if (n > 0) f(std::size_t{0}, n);
    return;
  }
  std::exception_ptr error;
  std::mutex error_mutex;
  auto run = [&](std::size_t b) {
    const std::size_t begin = n * b / blocks, end = n * (b + 1) / blocks;
    try {
      f(begin, end);
    } catch (...) {
      std::lock_guard lock(error_mutex);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(blocks - 1);
  for (std::size_t b = 1; b < blocks; ++b) threads.emplace_back(run, b);
  run(0);
  for (auto& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace halfback::detail
