// One job at a time on a thread of its own, for work that overlaps the caller's (the trainer
// builds the next step's batch while the GPU runs this one). The thread stays between jobs, so
// the OpenMP team a job starts is kept and reused by the next job instead of made anew.
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>

namespace fignet::detail {

class BackgroundTask {
 public:
  BackgroundTask() : thread_([this] { serve(); }) {}
  // Finishes the job in flight (dropping what it throws), then ends the thread.
  ~BackgroundTask() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;

  // Runs `job` on the task's thread; the job before it must have been waited for.
  void start(std::function<void()> job) {
    {
      std::lock_guard lock(mutex_);
      if (job_)
        throw std::logic_error("BackgroundTask::start: the previous job was not waited for");
      job_ = std::move(job);
    }
    changed_.notify_all();
  }

  // Blocks until the job started last has finished (at once when there is none); rethrows what
  // it threw.
  void wait() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !job_; });
    if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
  }

 private:
  void serve() {
    std::unique_lock lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return job_ || stopping_; });
      if (!job_) return;
      // Unlocked while it runs: start() refuses a new job until this one is cleared below.
      lock.unlock();
      std::exception_ptr failure;
      try {
        job_();
      } catch (...) {
        failure = std::current_exception();
      }
      lock.lock();
      failure_ = failure;
      job_ = nullptr;
      changed_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> job_;  // set from start() until the job has run
  std::exception_ptr failure_;
  bool stopping_ = false;
  std::thread thread_;  // last: starts once the members it reads exist
};

}  // namespace fignet::detail
