// A one-line progress bar with rate and ETA on stderr (redrawn in place on a terminal, printed
// every 10 % otherwise, so logs stay short).
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace fignet::cli {

class ProgressBar {
 public:
  ProgressBar(std::string label, long long total)
      : label_(std::move(label)),
        total_(total),
        start_(std::chrono::steady_clock::now()),
        terminal_(::isatty(STDERR_FILENO)) {}

  void update(long long done) {
    if (!terminal_ && done * 10 / std::max(1LL, total_) == last_decile_) return;
    last_decile_ = done * 10 / std::max(1LL, total_);
    const double elapsed = seconds();
    const double rate = elapsed > 0 ? done / elapsed : 0.0;
    const double eta = rate > 0 ? (total_ - done) / rate : 0.0;
    const int width = 30, filled = static_cast<int>(width * done / std::max(1LL, total_));
    std::fprintf(stderr, "%s%s [%s%s] %lld/%lld  %.1f/s  ETA %.0f s%s", terminal_ ? "\r" : "",
                 label_.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), done, total_, rate, eta,
                 terminal_ ? "" : "\n");
    std::fflush(stderr);
  }
  void finish(long long done) {
    last_decile_ = -1;
    update(done);
    if (terminal_) std::fputc('\n', stderr);
  }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::string label_;
  long long total_;
  std::chrono::steady_clock::time_point start_;
  bool terminal_;
  long long last_decile_ = -1;
};

}  // namespace fignet::cli
