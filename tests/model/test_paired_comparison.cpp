// compare_paired against exact cases (a constant ratio, ties), the sign test against binomial
// values computed by hand and by R's binom.test, and the bootstrap interval against the
// delta-method normal interval of a ratio of means on a large synthetic set.
#include "fignet/rollout/paired_comparison.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "../error_text.h"
#include "fignet/error.h"

namespace fignet {
namespace {

TEST(SignTest, MatchesBinomialTails) {
  // 8 of 10: 2·(C(10,0) + C(10,1) + C(10,2)) / 2^10.
  // (Binomial coefficients from lgamma: exact to ~1e-15.)
  EXPECT_NEAR(sign_test_p_value(8, 10), 2.0 * (1 + 10 + 45) / 1024.0, 1e-12);
  EXPECT_DOUBLE_EQ(sign_test_p_value(2, 10), sign_test_p_value(8, 10));
  EXPECT_NEAR(sign_test_p_value(0, 5), 2.0 / 32.0, 1e-12);
  EXPECT_DOUBLE_EQ(sign_test_p_value(5, 10), 1.0);  // the middle: capped at 1
  EXPECT_DOUBLE_EQ(sign_test_p_value(0, 0), 1.0);
  // binom.test(60, 100) in R: p-value = 0.05689 (large counts summed in log space).
  EXPECT_NEAR(sign_test_p_value(60, 100), 0.056887933, 1e-8);
  EXPECT_THROW(sign_test_p_value(11, 10), ConfigError);
}

TEST(PairedComparison, ConstantRatioHasANullInterval) {
  const std::vector<double> a = {0.2, 1.5, 0.7, 3.0, 0.05, 0.9};
  std::vector<double> b;
  for (double x : a) b.push_back(0.9 * x);
  const PairedComparison c = compare_paired(a, b);
  EXPECT_EQ(c.pairs, 6);
  EXPECT_NEAR(c.relative, -0.1, 1e-12);
  // Every resample has the same ratio.
  EXPECT_NEAR(c.relative_low, -0.1, 1e-12);
  EXPECT_NEAR(c.relative_high, -0.1, 1e-12);
  EXPECT_EQ(c.b_lower, 6);
  EXPECT_EQ(c.a_lower, 0);
  EXPECT_NEAR(c.sign_test_p, 2.0 / 64.0, 1e-12);
  EXPECT_NEAR(c.mean_b / c.mean_a, 0.9, 1e-12);
}

TEST(PairedComparison, IdenticalErrorsAreAllTies) {
  const std::vector<double> a = {0.3, 0.1, 0.8};
  const PairedComparison c = compare_paired(a, a);
  EXPECT_EQ(c.relative, 0.0);
  EXPECT_EQ(c.relative_low, 0.0);
  EXPECT_EQ(c.relative_high, 0.0);
  EXPECT_EQ(c.b_lower + c.a_lower, 0);
  EXPECT_EQ(c.sign_test_p, 1.0);
}

TEST(PairedComparison, BootstrapIntervalMatchesTheDeltaMethodOnALargeSet) {
  // Errors spread over a decade per scene, b 4 % lower on average with a 20 % scatter per scene.
  std::mt19937_64 engine(7);
  std::lognormal_distribution<double> scene(std::log(0.5), 0.8);
  std::normal_distribution<double> scatter(0.96, 0.2);
  const int n = 2000;
  std::vector<double> a(n), b(n);
  for (int i = 0; i < n; ++i) {
    a[i] = scene(engine);
    b[i] = a[i] * std::max(0.0, scatter(engine));
  }
  const PairedComparison c = compare_paired(a, b, {.resamples = 4000});

  // Delta method: R = Σb/Σa, var(R) ≈ var(b − R·a) / (n·mean(a)²).
  double sum_a = 0, sum_b = 0;
  for (int i = 0; i < n; ++i) sum_a += a[i], sum_b += b[i];
  const double ratio = sum_b / sum_a, mean_a = sum_a / n;
  double residual_sq = 0;
  for (int i = 0; i < n; ++i) residual_sq += std::pow(b[i] - ratio * a[i], 2);
  const double sd = std::sqrt(residual_sq / (n - 1) / n) / mean_a;
  const double half_width = 1.959964 * sd;
  EXPECT_NEAR(c.relative, ratio - 1.0, 1e-12);
  EXPECT_NEAR(c.relative_low, ratio - 1.0 - half_width, 0.1 * half_width);
  EXPECT_NEAR(c.relative_high, ratio - 1.0 + half_width, 0.1 * half_width);
  EXPECT_LT(c.relative_high, 0.0);  // 4 % on 2000 scenes is no chance
  EXPECT_LT(c.sign_test_p, 1e-6);
}

TEST(PairedComparison, SameSeedSameInterval) {
  const std::vector<double> a = {0.4, 0.9, 0.2, 1.1, 0.6, 0.3, 0.8};
  const std::vector<double> b = {0.5, 0.7, 0.25, 0.9, 0.65, 0.2, 0.85};
  const PairedComparison first = compare_paired(a, b), again = compare_paired(a, b);
  EXPECT_EQ(first.relative_low, again.relative_low);
  EXPECT_EQ(first.relative_high, again.relative_high);
  EXPECT_LT(first.relative_low, first.relative);
  EXPECT_GT(first.relative_high, first.relative);
  const PairedComparison other = compare_paired(a, b, {.seed = 2});
  EXPECT_NE(first.relative_low, other.relative_low);
}

// compare_paired(a, b, options) throws a ConfigError that says `expected`.
void expect_error(std::span<const double> a, std::span<const double> b, const std::string& expected,
                  const PairedComparisonOptions& options = {}) {
  const std::string message =
      testing::error_of<ConfigError>([&] { compare_paired(a, b, options); });
  EXPECT_NE(message.find(expected), std::string::npos) << message;
}

TEST(PairedComparison, BadInputNamesWhatIsWrong) {
  const std::vector<double> three = {0.1, 0.2, 0.3}, two = {0.1, 0.2};
  expect_error(three, two, "3 errors against 2");
  expect_error({}, {}, "no pairs");
  const std::vector<double> negative = {0.1, -0.2, 0.3};
  expect_error(three, negative, "b's error 1 is -0.2");
  const std::vector<double> not_finite = {0.1, NAN, 0.3};
  expect_error(not_finite, three, "a's error 1 is nan");
  const std::vector<double> zeros = {0, 0, 0};
  expect_error(zeros, three, "all zero");
  expect_error(three, three, "10 resamples", {.resamples = 10});
  expect_error(three, three, "confidence 1", {.confidence = 1.0});
  expect_error(not_finite, three, "models/old.h5's error 1 is nan",
               {.a_name = "models/old.h5", .b_name = "models/new.h5"});
  expect_error(three, negative, "models/new.h5's error 1 is -0.2",
               {.a_name = "models/old.h5", .b_name = "models/new.h5"});
  expect_error(zeros, three, "models/old.h5's errors are all zero", {.a_name = "models/old.h5"});
}

}  // namespace
}  // namespace fignet
