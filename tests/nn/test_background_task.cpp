// detail::BackgroundTask: a job runs on another thread and is done when wait() returns, its
// exception reaches wait() once, a second start before wait() is refused, and the destructor
// finishes a job in flight.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "parallel/background_task.h"

namespace fignet::detail {
namespace {

TEST(BackgroundTask, RunsEachJobOnItsOwnThreadAndIsDoneWhenWaitReturns) {
  BackgroundTask task;
  task.wait();  // nothing started: returns at once
  for (int i = 0; i < 3; ++i) {
    std::thread::id ran_on;
    int result = 0;
    task.start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      ran_on = std::this_thread::get_id();
      result = i + 1;
    });
    task.wait();
    EXPECT_EQ(result, i + 1);
    EXPECT_NE(ran_on, std::this_thread::get_id());
  }
}

TEST(BackgroundTask, AFailureReachesWaitOnceAndTheTaskGoesOn) {
  BackgroundTask task;
  task.start([] { throw std::runtime_error("job failed"); });
  EXPECT_THROW(task.wait(), std::runtime_error);
  task.wait();  // rethrown once only
  bool ran = false;
  task.start([&] { ran = true; });
  task.wait();
  EXPECT_TRUE(ran);
}

TEST(BackgroundTask, RefusesASecondJobBeforeTheFirstIsWaitedFor) {
  BackgroundTask task;
  std::atomic<bool> release{false};
  task.start([&] {
    while (!release) std::this_thread::yield();
  });
  EXPECT_THROW(task.start([] {}), std::logic_error);
  release = true;
  task.wait();
}

TEST(BackgroundTask, TheDestructorFinishesTheJobInFlight) {
  std::atomic<bool> finished{false};
  {
    BackgroundTask task;
    task.start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished = true;
    });
  }
  EXPECT_TRUE(finished);
  {
    BackgroundTask task;  // and drops what it threw
    task.start([] { throw std::runtime_error("dropped"); });
  }
}

}  // namespace
}  // namespace fignet::detail
