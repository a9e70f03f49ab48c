#include "fignet/rollout/one_step.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "fignet/error.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/rollout/rollout.h"
#include "per_trajectory_threads.h"

namespace fignet {

std::string_view regime_name(Regime regime) {
  switch (regime) {
    case Regime::kFreeFlight:
      return "free flight";
    case Regime::kContact:
      return "moving contact";
    case Regime::kRest:
      return "rest";
  }
  return "?";
}

void RegimeTotals::add(const RegimeTotals& other) {
  samples += other.samples;
  translation += other.translation;
  rotation += other.rotation;
  squared_sigmas += other.squared_sigmas;
  components += other.components;
  ahead += other.ahead;
  up += other.up;
}

OneStepTotals& OneStepTotals::operator+=(const OneStepTotals& other) {
  for (int r = 0; r < kRegimes; ++r) regimes[r].add(other.regimes[r]);
  impact_errors.add(other.impact_errors);
  unseen_impacts += other.unseen_impacts;
  return *this;
}

namespace {

constexpr size_t kRegimeValues = 7;

void append(const RegimeTotals& r, std::vector<double>& out) {
  out.insert(out.end(),
             {r.samples, r.translation, r.rotation, r.squared_sigmas, r.components, r.ahead, r.up});
}

RegimeTotals regime_from(const double* v) {
  return {v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
}

}  // namespace

// [each regime's 7 sums, the impacts' 7 sums, unseen impacts].
std::vector<double> OneStepTotals::serialize() const {
  std::vector<double> out;
  for (const RegimeTotals& r : regimes) append(r, out);
  append(impact_errors, out);
  out.push_back(unseen_impacts);
  return out;
}

OneStepTotals OneStepTotals::deserialize(std::span<const double> values) {
  constexpr size_t kSize = kRegimeValues * (kRegimes + 1) + 1;
  if (values.size() != kSize) {
    throw ConfigError("OneStepTotals: expected " + std::to_string(kSize) + " values, got " +
                      std::to_string(values.size()));
  }
  OneStepTotals totals;
  for (int r = 0; r < kRegimes; ++r) {
    totals.regimes[r] = regime_from(values.data() + kRegimeValues * r);
  }
  totals.impact_errors = regime_from(values.data() + kRegimeValues * kRegimes);
  totals.unseen_impacts = values[kSize - 1];
  return totals;
}

OneStepTotals one_step_totals(AccelerationPredictor& predictor, const GraphConfig& graph,
                              const Vec3& target_std, std::span<const Trajectory> truths,
                              const OneStepOptions& options) {
  if (!(target_std.array() > 0).all()) {
    throw ConfigError("one_step_totals: target_std must be positive");
  }
  const int h = predictor.history();
  if (h < 1 || graph.history != h) {
    throw ConfigError(
        fmt::format("one_step_totals: the predictor's history ({}) must be >= 1 "
                    "and equal the graph config's ({})",
                    h, graph.history));
  }
  GraphBuilder builder(graph);
  OneStepTotals totals;
  Scene scene;
  StepWorkspace workspace;  // integrate_next_poses reads its accelerations
  const Points& accelerations = workspace.accelerations;
  std::vector<Pose> next;
  std::vector<char> interacting;
  const Eigen::Array3d inverse_std = target_std.array().inverse();
  int done = 0;
  for (const Trajectory& truth : truths) {
    truth.validate();
    const double dt = truth.time_step;
    const double g = truth.gravity.norm();
    for (int t = h; t + 1 < truth.num_frames(); ++t) {
      scene_at_frame(truth, t, h, scene);
      builder.find_interacting_objects(scene, interacting);
      predictor.predict(scene, workspace.accelerations);
      integrate_next_poses(scene, next, workspace);
      Eigen::Index row = 0;
      for (size_t o = 0; o < scene.objects.size(); ++o) {
        const SceneObject& object = scene.objects[o];
        const Eigen::Index v = object.mesh->num_vertices();
        const Eigen::Index first = row;
        row += v;
        if (object.kinematic) continue;
        const std::vector<Pose>& poses = truth.objects[o].poses;
        const Pose &before = poses[t - 1], &now = poses[t], &after = poses[t + 1];
        // The truth's motion over the step.
        const double speed = (after.position - now.position).norm() / dt;
        const double angular_speed = now.orientation.angularDistance(after.orientation) / dt;
        const bool edge = interacting[o] != 0;
        const bool impact = is_impact(truth, o, t, options.impact_g);
        if (impact && !edge) totals.unseen_impacts += 1;
        const Regime regime =
            !edge ? Regime::kFreeFlight
            : speed < options.rest_speed && angular_speed < options.rest_angular_speed
                ? Regime::kRest
                : Regime::kContact;
        // The centre's error, whole and signed along the incoming motion and against gravity.
        RegimeTotals step;
        step.samples = 1;
        const Vec3 error = next[o].position - after.position;
        step.translation = error.norm();
        step.rotation =
            next[o].orientation.angularDistance(after.orientation) * 180.0 / std::numbers::pi;
        const Vec3 incoming = now.position - before.position;
        if (incoming.norm() > 0) step.ahead = error.dot(incoming.normalized());
        if (g > 0) step.up = -error.dot(truth.gravity / g);
        // Vertex accelerations in the model's normalised units.
        const Points truth_next = posed_vertices(*object.mesh, after);
        const Points true_acceleration =
            truth_next - 2.0 * object.positions_at(h) + object.positions_at(h - 1);
        const Points vertex_error = accelerations.middleRows(first, v) - true_acceleration;
        step.squared_sigmas =
            (vertex_error.array().rowwise() * inverse_std.transpose()).square().sum();
        step.components = 3.0 * static_cast<double>(v);
        totals.regimes[static_cast<int>(regime)].add(step);
        if (impact) totals.impact_errors.add(step);
      }
    }
    if (options.on_trajectory) options.on_trajectory(++done);
  }
  return totals;
}

OneStepTotals one_step_totals_parallel(
    const std::function<std::unique_ptr<AccelerationPredictor>()>& make_predictor,
    const GraphConfig& graph, const Vec3& target_std, std::span<const Trajectory> truths,
    int threads, const OneStepOptions& options) {
  OneStepOptions quiet = options;
  quiet.on_trajectory = nullptr;
  std::vector<OneStepTotals> each(truths.size());
  detail::for_each_trajectory(make_predictor, static_cast<int>(truths.size()), threads,
                              [&](AccelerationPredictor& predictor, int i) {
                                each[i] = one_step_totals(predictor, graph, target_std,
                                                          truths.subspan(i, 1), quiet);
                              });
  OneStepTotals totals;
  for (const OneStepTotals& t : each) totals += t;
  return totals;
}

double mean_translation(const RegimeTotals& totals) {
  return totals.samples > 0 ? totals.translation / totals.samples : 0.0;
}

double mean_ahead(const RegimeTotals& totals) {
  return totals.samples > 0 ? totals.ahead / totals.samples : 0.0;
}

double mean_up(const RegimeTotals& totals) {
  return totals.samples > 0 ? totals.up / totals.samples : 0.0;
}

double rms_sigmas(const RegimeTotals& totals) {
  return totals.components > 0 ? std::sqrt(totals.squared_sigmas / totals.components) : 0.0;
}

}  // namespace fignet
