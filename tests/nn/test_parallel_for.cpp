// detail::parallel_for: every index once, thread indices for per-thread scratch, and an exception
// in one iteration rethrown to the caller (never through the OpenMP region, which would abort).
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "parallel/parallel_for.h"

namespace fignet::detail {
namespace {

TEST(ParallelFor, RunsEveryIndexOnceWithThreadIndicesInRange) {
  for (Schedule schedule : {Schedule::kContiguous, Schedule::kOneAtATime}) {
    for (int threads : {1, 2, 4}) {
      constexpr int kN = 37;
      std::vector<std::atomic<int>> runs(kN);
      std::atomic<int> out_of_range{0};
      parallel_for(kN, threads, schedule, [&](int i, int thread) {
        runs[i].fetch_add(1);
        if (thread < 0 || thread >= threads) out_of_range.fetch_add(1);
      });
      for (int i = 0; i < kN; ++i) EXPECT_EQ(runs[i].load(), 1) << "index " << i;
      EXPECT_EQ(out_of_range.load(), 0) << threads << " threads";
    }
  }
}

TEST(ParallelFor, AFailureReachesTheCallerAndTheOtherIterationsRun) {
  for (Schedule schedule : {Schedule::kContiguous, Schedule::kOneAtATime}) {
    std::atomic<int> finished{0};
    try {
      parallel_for(8, 4, schedule, [&](int i) {
        if (i == 5) throw std::runtime_error("iteration 5 failed");
        finished.fetch_add(1);
      });
      FAIL() << "no exception reached the caller";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "iteration 5 failed");
    }
    EXPECT_EQ(finished.load(), 7);
  }
}

TEST(ParallelFor, ATeamOfOneRunsOnTheCallersThreadWithoutARegion) {
  // Nested code must see the caller's team (gemm keeps its products single-threaded inside one).
  int level_inside = -1;
  parallel_for(3, 1, Schedule::kContiguous, [&](int) { level_inside = omp_get_level(); });
  EXPECT_EQ(level_inside, omp_get_level());
}

// Fixed blocks: the same [begin, end) ranges for any thread count, covering [0, n) once, the last
// one partial.
TEST(ParallelForBlocks, CoversEveryIndexOnceInTheSameBlocksForAnyThreadCount) {
  const size_t n = 2 * 100 + 7;
  for (const int threads : {1, 3}) {
    std::vector<int> visits(n, 0);
    std::vector<std::pair<size_t, size_t>> ranges(3);
    parallel_for_blocks(n, 100, threads, [&](size_t begin, size_t end) {
      ranges[begin / 100] = {begin, end};
      for (size_t i = begin; i < end; ++i) ++visits[i];
    });
    EXPECT_EQ(visits, std::vector<int>(n, 1)) << threads << " threads";
    EXPECT_EQ(ranges, (std::vector<std::pair<size_t, size_t>>{{0, 100}, {100, 200}, {200, 207}}));
  }
}

}  // namespace
}  // namespace fignet::detail
