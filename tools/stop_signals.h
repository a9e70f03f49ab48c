// Ctrl-C and SIGTERM as a request to stop between training steps, never delivered in the middle
// of one. A handler that interrupts a step runs on the stack of whatever code is executing, JIT
// code of the product engine included: stopped training runs aborted with glibc's "corrupted
// size vs. prev_size" inside oneDNN's sgemm in the step after the signal (2 of 8 release runs
// signalled mid-step; none of the runs that were not signalled). So the signals are blocked
// while the object lives, in the calling thread and the threads it starts later (OpenMP's), and
// taken synchronously by requested(). Threads started before (MPI's) may still receive them:
// for those a handler only sets a flag.
#pragma once

#include <pthread.h>

#include <csignal>
#include <ctime>

namespace fignet::cli {

class StopSignals {
 public:
  StopSignals() {
    sigemptyset(&signals_);
    sigaddset(&signals_, SIGINT);
    sigaddset(&signals_, SIGTERM);
    flag() = 0;
    previous_int_ = std::signal(SIGINT, set_flag);
    previous_term_ = std::signal(SIGTERM, set_flag);
    pthread_sigmask(SIG_BLOCK, &signals_, &previous_mask_);
  }
  ~StopSignals() {
    // A signal that came after the last check is taken here, not by the handlers restored below.
    while (take_pending()) {
    }
    pthread_sigmask(SIG_SETMASK, &previous_mask_, nullptr);
    std::signal(SIGINT, previous_int_);
    std::signal(SIGTERM, previous_term_);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // Whether Ctrl-C or SIGTERM came since construction (each call takes what is pending).
  bool requested() {
    if (take_pending()) flag() = 1;
    return flag() != 0;
  }

 private:
  static volatile std::sig_atomic_t& flag() {
    static volatile std::sig_atomic_t requested = 0;
    return requested;
  }
  static void set_flag(int) { flag() = 1; }
  bool take_pending() {
    const timespec now{0, 0};
    return sigtimedwait(&signals_, nullptr, &now) > 0;
  }

  sigset_t signals_, previous_mask_;
  void (*previous_int_)(int) = SIG_DFL;
  void (*previous_term_)(int) = SIG_DFL;
};

}  // namespace fignet::cli
