#include "fignet/rollout/paired_comparison.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fignet/error.h"

namespace fignet {

namespace {

// A uniform index below `n` from one 64-bit draw (multiply-shift): the same on every standard
// library, unlike std::uniform_int_distribution.
std::size_t draw_index(std::mt19937_64& engine, std::size_t n) {
  return static_cast<std::size_t>((static_cast<unsigned __int128>(engine()) * n) >> 64);
}

// The q-quantile of sorted values, interpolated between neighbours.
double quantile(const std::vector<double>& sorted, double q) {
  const double at = q * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(at));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  return sorted[below] + (at - static_cast<double>(below)) * (sorted[above] - sorted[below]);
}

void check_errors(std::span<const double> values, const std::string& which) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]) || values[i] < 0) {
      throw ConfigError(
          fmt::format("paired comparison: {}'s error {} is {}: errors must be "
                      "finite and not negative",
                      which, i, values[i]));
    }
  }
}

}  // namespace

double sign_test_p_value(int wins, int trials) {
  if (trials < 0 || wins < 0 || wins > trials) {
    throw ConfigError(fmt::format("sign test: {} wins in {} trials", wins, trials));
  }
  if (trials == 0) return 1.0;
  // Twice the tail of the rarer side, summed in log space so that large counts do not overflow.
  const int tail = std::min(wins, trials - wins);
  const double log_half_power = trials * std::log(0.5);
  double p = 0.0;
  for (int i = 0; i <= tail; ++i) {
    const double log_choose =
        std::lgamma(trials + 1.0) - std::lgamma(i + 1.0) - std::lgamma(trials - i + 1.0);
    p += std::exp(log_choose + log_half_power);
  }
  return std::min(1.0, 2.0 * p);
}

PairedComparison compare_paired(std::span<const double> a, std::span<const double> b,
                                const PairedComparisonOptions& options) {
  if (a.size() != b.size()) {
    throw ConfigError(
        fmt::format("paired comparison: {} errors against {}: the pairs must be "
                    "the same scenes",
                    a.size(), b.size()));
  }
  if (a.empty()) throw ConfigError("paired comparison: no pairs");
  if (options.resamples < 100) {
    throw ConfigError(
        fmt::format("paired comparison: {} resamples (at least 100)", options.resamples));
  }
  if (!(options.confidence > 0 && options.confidence < 1)) {
    throw ConfigError(
        fmt::format("paired comparison: confidence {} is not between 0 and 1", options.confidence));
  }
  check_errors(a, options.a_name);
  check_errors(b, options.b_name);
  const std::size_t n = a.size();

  PairedComparison result;
  result.pairs = static_cast<int>(n);
  double sum_a = 0, sum_b = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sum_a += a[i];
    sum_b += b[i];
    result.b_lower += b[i] < a[i];
    result.a_lower += a[i] < b[i];
  }
  if (sum_a == 0) {
    throw ConfigError(fmt::format("paired comparison: {}'s errors are all zero", options.a_name));
  }
  result.mean_a = sum_a / static_cast<double>(n);
  result.mean_b = sum_b / static_cast<double>(n);
  result.relative = sum_b / sum_a - 1.0;
  result.sign_test_p = sign_test_p_value(result.b_lower, result.b_lower + result.a_lower);

  // Resample the scenes, each drawn with both of its errors. A resample of only zero errors of
  // a has no ratio and is left out (a few at most, and only when most of a's errors are zero).
  std::mt19937_64 engine(options.seed);
  std::vector<double> relatives;
  relatives.reserve(static_cast<std::size_t>(options.resamples));
  for (int r = 0; r < options.resamples; ++r) {
    double resampled_a = 0, resampled_b = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = draw_index(engine, n);
      resampled_a += a[i];
      resampled_b += b[i];
    }
    if (resampled_a > 0) relatives.push_back(resampled_b / resampled_a - 1.0);
  }
  if (relatives.empty()) relatives.push_back(result.relative);
  std::sort(relatives.begin(), relatives.end());
  const double tail = (1.0 - options.confidence) / 2.0;
  result.relative_low = quantile(relatives, tail);
  result.relative_high = quantile(relatives, 1.0 - tail);
  return result;
}

}  // namespace fignet
