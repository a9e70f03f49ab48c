// A one-line progress bar with rate and ETA on stderr (redrawn in place on a terminal, printed
// every 10 % otherwise, so logs stay short).
#pragma once

#include <unistd.h>

#include <fmt/format.h>
#include <chrono>
#include <cstdio>
#include <string>

namespace fignet::cli {

class ProgressBar {
 public:
  // `first` is where counting starts (a resumed run's step), so rates and ETA cover this run.
  ProgressBar(std::string label, long long total, long long first = 0)
      : label_(std::move(label)),
        total_(total),
        first_(first),
        start_(std::chrono::steady_clock::now()),
        terminal_(::isatty(STDERR_FILENO)) {}

  // `detail` (loss, rate) is printed after the counts.
  void update(long long done, const std::string& detail = "") {
    if (!detail.empty()) detail_ = detail;
    if (!terminal_ && done * 10 / std::max(1LL, total_) == last_decile_) return;
    last_decile_ = done * 10 / std::max(1LL, total_);
    const double elapsed = seconds();
    const double rate = elapsed > 0 ? (done - first_) / elapsed : 0.0;
    const double eta = rate > 0 ? (total_ - done) / rate : 0.0;
    const int width = 30, filled = static_cast<int>(width * done / std::max(1LL, total_));
    fmt::print(stderr, "{}{} [{}{}] {}/{}  {}  ETA {:.0f} s{}", terminal_ ? "\r" : "", label_,
               std::string(filled, '#'), std::string(width - filled, '.'), done, total_,
               detail_.empty() ? fmt::format("{:.1f}/s", rate) : detail_, eta,
               terminal_ ? "\x1b[K" : "\n");
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
  long long total_, first_;
  std::string detail_;
  std::chrono::steady_clock::time_point start_;
  bool terminal_;
  long long last_decile_ = -1;
};

}  // namespace fignet::cli
