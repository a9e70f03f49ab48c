// body(0..n-1) shared among an OpenMP team, for bodies that may throw. An exception must not
// leave a parallel region (the runtime would terminate), so in a team each iteration's is caught,
// the first kept and rethrown once the team has joined (the other iterations still run).
#pragma once

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <exception>
#include <type_traits>

namespace fignet::detail {

enum class Schedule {
  kContiguous,  // each thread one contiguous range (even work)
  kOneAtATime,  // the next index to the next idle thread (uneven work)
};

// Runs on min(threads, n) threads, or on the calling thread alone when that is one (no parallel
// region, so nested code still sees the caller's team). A body that takes (i, thread) also gets
// its thread's index in [0, min(threads, n)), for per-thread scratch.
template <class Body>  // void(int i) or void(int i, int thread)
void parallel_for(int n, int threads, Schedule schedule, Body&& body) {
  auto call = [&](int i, int thread) {
    if constexpr (std::is_invocable_v<Body&, int, int>) {
      body(i, thread);
    } else {
      body(i);
    }
  };
  const int team = std::min(threads, n);
  if (team <= 1) {
    for (int i = 0; i < n; ++i) call(i, 0);
    return;
  }
  std::exception_ptr failure;
  auto run = [&](int i) {
    try {
      call(i, omp_get_thread_num());
    } catch (...) {
#pragma omp critical(fignet_parallel_for_failure)
      if (!failure) failure = std::current_exception();
    }
  };
  if (schedule == Schedule::kContiguous) {
#pragma omp parallel for num_threads(team) schedule(static)
    for (int i = 0; i < n; ++i) run(i);
  } else {
#pragma omp parallel for num_threads(team) schedule(dynamic, 1)
    for (int i = 0; i < n; ++i) run(i);
  }
  if (failure) std::rethrow_exception(failure);
}

// body(begin, end) over [0, n) in fixed blocks of `block` indices shared among `threads`: each
// index is handled by the same code whatever the thread count, so elementwise results do not
// depend on it.
template <class Body>  // void(size_t begin, size_t end)
void parallel_for_blocks(size_t n, size_t block, int threads, Body&& body) {
  const int blocks = static_cast<int>((n + block - 1) / block);
  parallel_for(blocks, threads, Schedule::kContiguous, [&](int b) {
    const size_t begin = static_cast<size_t>(b) * block;
    body(begin, std::min(n, begin + block));
  });
}

}  // namespace fignet::detail
