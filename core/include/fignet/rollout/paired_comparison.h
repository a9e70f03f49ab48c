// Two models' errors on the same trajectories, compared pair by pair. Rollout errors differ by
// 10× from scene to scene, so two means over the same 20–100 scenes differ far less than their
// own spreads suggest; what tells a real difference from chance is the spread of the per-scene
// differences. The relative difference of the means gets a paired bootstrap interval and the
// count of scenes each model wins a sign test, so a recipe comparison says how sure it is.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace fignet {

struct PairedComparison {
  int pairs = 0;
  double mean_a = 0, mean_b = 0;
  // mean_b / mean_a − 1: −0.05 when b's mean error is 5 % lower.
  double relative = 0;
  // Percentile interval of `relative` (95 % by default) over bootstrap resamples of the pairs:
  // each resample draws `pairs` pairs with replacement, keeping a and b of a scene together.
  double relative_low = 0, relative_high = 0;
  int b_lower = 0, a_lower = 0;  // scenes where one error is lower; the rest are ties
  // Two-sided exact sign test of b_lower against a_lower (ties left out): the chance of a split
  // at least this uneven when either model is equally likely to win a scene; 1 without winners.
  double sign_test_p = 1;
};

struct PairedComparisonOptions {
  int resamples = 10000;
  double confidence = 0.95;
  std::uint64_t seed = 1;  // the same seed gives the same interval on every platform
  // What error messages call the two runs (e.g. the models' paths).
  std::string a_name = "a", b_name = "b";
};

// Throws ConfigError when the spans differ in length or are empty, when a value is negative or
// not finite, or when a's errors are all zero (no relative difference); the message names the
// runs by `a_name` and `b_name`.
PairedComparison compare_paired(std::span<const double> a, std::span<const double> b,
                                const PairedComparisonOptions& options = {});

// The two-sided exact binomial test of `wins` successes in `trials` at p = 1/2.
double sign_test_p_value(int wins, int trials);

}  // namespace fignet
