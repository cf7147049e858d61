#include "halfback/core/parallel.hpp"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace halfback {

int thread_count(int threads) {
  if (threads < 0)
    throw std::invalid_argument(
        "threads: " + std::to_string(threads) +
        " is negative (0 = all cores, 1 = the calling thread, n = at most n)");
  // The threads available to this process (TBB reads the affinity mask): more would only
  // oversubscribe.
  const int hardware = std::max(1, tbb::info::default_concurrency());
  return threads == 0 ? hardware : std::min(threads, hardware);
}

void parallel_for(std::size_t n, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body, int threads) {
  grain = std::max<std::size_t>(grain, 1);
  const int count = thread_count(threads);
  if (count == 1 || n < 2 * grain) {
    if (n > 0) body(0, n);
    return;
  }
  auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  };
  // An arena only when the caller limits the threads: the default one already has them all.
  if (threads == 0 || count >= tbb::info::default_concurrency()) {
    run();
  } else {
    tbb::task_arena arena(count);
    arena.execute(run);
  }
}

}  // namespace halfback
