// The metrics of `fignet eval` on Python inputs: per-frame translation (RMSE over dynamic
// objects) and rotation errors of a rollout, from trajectories or from numpy poses, a whole
// evaluation of a model over a set of trajectories, and two runs' errors compared scene by scene.
#include <pybind11/stl.h>

#include <cstdint>

#include <fmt/format.h>

#include "bindings.h"
#include "fignet/rollout/evaluation.h"
#include "fignet/rollout/paired_comparison.h"

namespace fignet::python {

namespace {

py::array_t<double> vector_array(const std::vector<double>& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

py::dict errors_dict(const RolloutErrors& e) {
  py::dict out;
  out["translation"] = vector_array(e.translation);
  out["rotation"] = vector_array(e.rotation);
  out["mean_translation"] = e.mean_translation;
  out["final_translation"] = e.final_translation;
  out["mean_rotation"] = e.mean_rotation;
  out["final_rotation"] = e.final_rotation;
  out["predicted_travel"] = e.predicted_travel;
  out["true_travel"] = e.true_travel;
  return out;
}

// Poses (T, N, 3) and (T, N, 4) as a mesh-less trajectory: all rollout_errors reads.
Trajectory poses_only(const py::handle& positions, const py::handle& quaternions,
                      const std::vector<bool>& kinematic, const char* what) {
  const DoubleArray p = double_array(positions), q = double_array(quaternions);
  if (!p || p.ndim() != 3 || p.shape(2) != 3) {
    throw py::value_error(fmt::format("{}: positions must have shape (frames, objects, 3)", what));
  }
  if (!q || q.ndim() != 3 || q.shape(2) != 4 || q.shape(0) != p.shape(0) ||
      q.shape(1) != p.shape(1)) {
    throw py::value_error(fmt::format(
        "{}: quaternions must have shape (frames, objects, 4) with the positions' frames and "
        "objects ({}, {})",
        what, p.shape(0), p.shape(1)));
  }
  if (!kinematic.empty() && static_cast<py::ssize_t>(kinematic.size()) != p.shape(1)) {
    throw py::value_error(
        fmt::format("kinematic: {} flags for {} objects", kinematic.size(), p.shape(1)));
  }
  Trajectory t;
  t.objects.resize(static_cast<size_t>(p.shape(1)));
  const auto pa = p.unchecked<3>();
  const auto qa = q.unchecked<3>();
  for (py::ssize_t o = 0; o < p.shape(1); ++o) {
    TrajectoryObject& object = t.objects[o];
    object.kinematic = kinematic.empty() ? false : kinematic[o];
    object.poses.resize(static_cast<size_t>(p.shape(0)));
    for (py::ssize_t f = 0; f < p.shape(0); ++f) {
      object.poses[f].position = Vec3(pa(f, o, 0), pa(f, o, 1), pa(f, o, 2));
      object.poses[f].orientation = read_wxyz(qa.data(f, o, 0));
    }
  }
  return t;
}

void check_matching(const Trajectory& predicted, const Trajectory& truth) {
  if (predicted.objects.size() != truth.objects.size()) {
    throw py::value_error(fmt::format("the prediction has {} objects, the truth {}",
                                      predicted.objects.size(), truth.objects.size()));
  }
}

}  // namespace

void bind_evaluation(py::module_& m) {
  m.def(
      "rollout_errors",
      [](const Trajectory& predicted, const Trajectory& truth, int first_predicted) {
        check_matching(predicted, truth);
        return errors_dict(rollout_errors(predicted, truth, first_predicted));
      },
      py::arg("predicted"), py::arg("truth"), py::arg("first_predicted") = 3,
      R"(Errors of a rollout against the truth as `fignet eval` computes them: per frame, the
"translation" RMSE over dynamic objects of the centre-of-mass error (m) and the mean "rotation"
angle (degrees); their means over frames first_predicted … end and their last values.)");
  m.def(
      "pose_errors",
      [](const py::handle& positions, const py::handle& quaternions,
         const py::handle& true_positions, const py::handle& true_quaternions, int first_predicted,
         std::optional<std::vector<bool>> kinematic) {
        const std::vector<bool> flags = kinematic.value_or(std::vector<bool>{});
        const Trajectory predicted = poses_only(positions, quaternions, flags, "predicted");
        const Trajectory truth = poses_only(true_positions, true_quaternions, flags, "truth");
        check_matching(predicted, truth);
        return errors_dict(rollout_errors(predicted, truth, first_predicted));
      },
      py::arg("positions"), py::arg("quaternions"), py::arg("true_positions"),
      py::arg("true_quaternions"), py::arg("first_predicted") = 3,
      py::arg("kinematic") = py::none(),
      "rollout_errors on numpy poses: positions (frames, objects, 3), quaternions (frames, "
      "objects, 4) as (w, x, y, z); `kinematic` flags objects left out of the errors.");
  m.def(
      "evaluate",
      [](const std::shared_ptr<Model>& model, const std::vector<Trajectory>& trajectories,
         int frames, bool penetration, int threads, int turns, bool mirror) {
        if (trajectories.empty()) throw py::value_error("evaluate: no trajectories");
        for (const Trajectory& t : trajectories) t.validate();
        const PredictionOptions prediction{.threads = 1, .turns = turns, .mirror = mirror};
        prediction.validate();  // here, not in the worker threads
        EvaluationOptions options;
        options.frames = frames;
        options.penetration = penetration;
        Evaluation e;
        {
          py::gil_scoped_release release;
          const std::shared_ptr<const Model> shared = model;
          e = evaluate_rollouts_parallel(
              [&] { return std::make_unique<ModelPredictor>(shared, prediction); }, trajectories,
              std::max(1, threads), options);
        }
        py::dict out;
        out["trajectories"] = e.trajectories;
        out["mean_translation_m"] = e.mean_translation;
        out["final_translation_m"] = e.final_translation;
        out["mean_rotation_deg"] = e.mean_rotation;
        out["final_rotation_deg"] = e.final_rotation;
        out["travel_ratio"] = e.travel_ratio;
        out["penetration_depth_ratio"] = e.penetration_depth_ratio;
        out["penetration_count_ratio"] = e.penetration_count_ratio;
        out["face_edges_per_step"] = e.face_edges_per_step;
        out["milliseconds_per_step"] = e.milliseconds_per_step;
        out["translation_per_frame_m"] = vector_array(e.translation);
        out["rotation_per_frame_deg"] = vector_array(e.rotation);
        py::list per_trajectory;
        for (const RolloutErrors& r : e.per_trajectory) per_trajectory.append(errors_dict(r));
        out["per_trajectory"] = per_trajectory;
        return out;
      },
      py::arg("model"), py::arg("trajectories"), py::arg("frames") = -1,
      py::arg("penetration") = false, py::arg("threads") = 1, py::arg("turns") = 1,
      py::arg("mirror") = false,
      R"(Rolls every trajectory out with the network alone and summarises as `fignet eval --json`
does (the same keys; `turns` and `mirror` as its --turns and --mirror): mean and last-frame errors averaged over trajectories, per-frame means,
penetration ratios when asked (costly), and each trajectory's errors.)");
  m.def(
      "compare_paired",
      [](const std::vector<double>& a, const std::vector<double>& b, int resamples,
         double confidence, std::uint64_t seed) {
        const PairedComparisonOptions options{
            .resamples = resamples, .confidence = confidence, .seed = seed};
        const PairedComparison c = compare_paired(a, b, options);
        py::dict out;
        out["pairs"] = c.pairs;
        out["mean_a"] = c.mean_a;
        out["mean_b"] = c.mean_b;
        out["relative"] = c.relative;
        out["relative_low"] = c.relative_low;
        out["relative_high"] = c.relative_high;
        out["b_lower"] = c.b_lower;
        out["a_lower"] = c.a_lower;
        out["sign_test_p"] = c.sign_test_p;
        return out;
      },
      py::arg("a"), py::arg("b"), py::arg("resamples") = 10000, py::arg("confidence") = 0.95,
      py::arg("seed") = 1,
      R"(Two runs' errors on the same scenes (a[i] and b[i] of scene i), as `fignet eval`
compares each model with the first: "relative" is mean(b) / mean(a) - 1, "relative_low" and
"relative_high" its percentile interval (`confidence`) over `resamples` bootstrap resamples of
the scenes (each drawn with both errors), "b_lower" / "a_lower" the scenes each run's error is
the lower on (ties in neither) and "sign_test_p" the two-sided exact sign test of that split.
The same seed gives the same interval as `fignet eval`. Raises ConfigError on lists of different
lengths, negative or non-finite errors, or a's errors all zero.)");
}

}  // namespace fignet::python
