// The one parallel loop of halfback, on oneTBB. Every layer runs its parallel work through it, so
// that `threads` means the same everywhere:
//   0  all hardware threads (what the process may use),
//   1  the calling thread only (no task is spawned),
//   n  at most n threads.
#pragma once

#include <cstddef>
#include <functional>

namespace halfback {

// The number of threads a `threads` setting stands for on this machine (>= 1). Throws
// std::invalid_argument for a negative setting.
int thread_count(int threads);

// Runs body(begin, end) over disjoint blocks covering [0, n) on up to thread_count(threads)
// threads; returns when all blocks are done. oneTBB cuts the range in halves down to blocks of
// `grain` items at most where there is work to balance, and keeps larger blocks elsewhere: a block
// holds at least grain/2 items. With one thread, or fewer than 2 × grain items, body(0, n) runs
// once on the calling thread. An exception thrown
// by a block is rethrown on the calling thread (the other blocks may or may not have run).
// Blocks may run in any order: a body must not depend on how the range is cut.
void parallel_for(std::size_t n, std::size_t grain,
                  const std::function<void(std::size_t begin, std::size_t end)>& body,
                  int threads = 0);

}  // namespace halfback
