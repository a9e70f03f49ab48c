// One-step errors split by what the input graph shows of each object (issue 13's diagnostics):
// from every ground-truth frame, the predicted next pose of each dynamic object against the
// truth, grouped into free flight (no collision edge), moving contact and rest (in contact, the
// truth nearly still); and impacts the predictor could not see: a large acceleration of an object
// that had no collision edge in its input.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "fignet/data/trajectory.h"
#include "fignet/graph/config.h"
#include "fignet/rollout/predictor.h"

namespace fignet {

enum class Regime { kFreeFlight = 0, kContact = 1, kRest = 2 };
inline constexpr int kRegimes = 3;
std::string_view regime_name(Regime regime);

struct OneStepOptions {
  // Rest: in contact and, in the truth, moving slower than these over the predicted step.
  double rest_speed = kRestSpeed;    // m/s of the centre of mass
  double rest_angular_speed = 0.25;  // rad/s
  // Impact: the truth's centre-of-mass acceleration differs from gravity by more than this many
  // g (is_impact).
  double impact_g = kImpactG;
  std::function<void(int done)> on_trajectory;  // progress: called after each trajectory
};

// Sums, so that shares of trajectories (threads, processes) add up.
struct RegimeTotals {
  double samples = 0;         // object-steps
  double translation = 0;     // Σ |x̂ − x| of the centre of mass, metres
  double rotation = 0;        // Σ angle between predicted and true orientation, degrees
  double squared_sigmas = 0;  // Σ over vertex components of ((â − a)/σ)², σ: the target's std
  double components = 0;      // vertex components summed there
  // Signed parts of x̂ − x, metres, which a mean |x̂ − x| hides: a bias adds up over a rollout
  // where noise partly cancels. `ahead`: along the centre's motion into the step (x_t − x_{t−1};
  // > 0: the body keeps more of its speed than the truth, e.g. too little friction or too soft an
  // impact); `up`: against gravity (> 0: falls or bounces less deep, rises more).
  double ahead = 0, up = 0;
  void add(const RegimeTotals& other);
};

struct OneStepTotals {
  std::array<RegimeTotals, kRegimes> regimes{};
  // The impacts' errors (every regime's object-steps whose truth is an impact; their count is
  // impact_errors.samples): one impact's error becomes a velocity error that a rollout carries
  // from then on.
  RegimeTotals impact_errors;
  double unseen_impacts = 0;  // object-steps of those with no collision edge in their input
  OneStepTotals& operator+=(const OneStepTotals& other);
  std::vector<double> serialize() const;
  static OneStepTotals deserialize(std::span<const double> values);
};

// One-step predictions from every frame t ≥ h with a next frame. Regimes come from a graph built
// with `graph` (the model's config; the builder's own pair search). `target_std` scales vertex
// acceleration errors into the model's normalised units (per component).
OneStepTotals one_step_totals(AccelerationPredictor& predictor, const GraphConfig& graph,
                              const Vec3& target_std, std::span<const Trajectory> truths,
                              const OneStepOptions& options = {});

// The same with the trajectories shared among `threads` threads, each with a predictor of its own
// from `make_predictor`; totals are summed in trajectory order, so they equal the one-thread
// result (on_trajectory is not called).
OneStepTotals one_step_totals_parallel(
    const std::function<std::unique_ptr<AccelerationPredictor>()>& make_predictor,
    const GraphConfig& graph, const Vec3& target_std, std::span<const Trajectory> truths,
    int threads, const OneStepOptions& options = {});

// Per regime: mean translation error in metres and vertex-acceleration RMS in σ (0 when the
// regime has no sample).
double mean_translation(const RegimeTotals& totals);
// Mean signed errors (metres) along the incoming motion and against gravity (0 without samples).
double mean_ahead(const RegimeTotals& totals);
double mean_up(const RegimeTotals& totals);
double rms_sigmas(const RegimeTotals& totals);

}  // namespace fignet
