// The parallel loop: every item once, one meaning of `threads`, exceptions reach the caller.
#include "halfback/core/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace halfback {
namespace {

TEST(ParallelFor, CoversTheRangeOnceInBlocksOfAboutTheGrain) {
  for (int threads : {0, 1, 2, 3}) {
    const std::size_t n = 100003, grain = 100;
    std::vector<std::atomic<int>> hits(n);
    std::atomic<std::size_t> smallest{n}, largest{0};
    parallel_for(
        n, grain,
        [&](std::size_t begin, std::size_t end) {
          ASSERT_LT(begin, end);
          for (std::size_t s = smallest;
               end - begin < s && !smallest.compare_exchange_weak(s, end - begin);) {
          }
          for (std::size_t l = largest;
               end - begin > l && !largest.compare_exchange_weak(l, end - begin);) {
          }
          for (std::size_t i = begin; i < end; ++i) ++hits[i];
        },
        threads);
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i], 1) << i;
    if (thread_count(threads) == 1) {
      EXPECT_EQ(smallest, n);  // one call, the whole range
    } else {
      EXPECT_GE(smallest, grain / 2) << threads;
      EXPECT_LT(largest, n) << threads;  // cut
    }
  }
}

TEST(ParallelFor, OneThreadIsTheCallingThread) {
  const auto caller = std::this_thread::get_id();
  std::mutex m;
  std::set<std::thread::id> ids;
  parallel_for(
      1 << 16, 1,
      [&](std::size_t, std::size_t) {
        std::lock_guard lock(m);
        ids.insert(std::this_thread::get_id());
      },
      1);
  EXPECT_EQ(ids, std::set<std::thread::id>{caller});
}

TEST(ParallelFor, ThreadCountMeaning) {
  const int all = thread_count(0);
  EXPECT_GE(all, 1);
  EXPECT_EQ(thread_count(1), 1);
  EXPECT_EQ(thread_count(all + 5), all);
  EXPECT_THROW(thread_count(-1), std::invalid_argument);
  EXPECT_THROW(parallel_for(
                   10, 1, [](std::size_t, std::size_t) {}, -2),
               std::invalid_argument);
}

TEST(ParallelFor, AtMostNThreads) {
  std::atomic<int> running{0}, peak{0};
  parallel_for(
      64, 1,
      [&](std::size_t, std::size_t) {
        const int now = ++running;
        for (int p = peak; now > p && !peak.compare_exchange_weak(p, now);) {
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        --running;
      },
      2);
  EXPECT_LE(peak, 2);
}

TEST(ParallelFor, ExceptionsReachTheCaller) {
  EXPECT_THROW(parallel_for(
                   1000, 1,
                   [](std::size_t begin, std::size_t end) {
                     if (begin <= 500 && 500 < end) throw std::runtime_error("block with 500");
                   },
                   0),
               std::runtime_error);
  int calls = 0;
  parallel_for(0, 1, [&](std::size_t, std::size_t) { ++calls; });
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace halfback
