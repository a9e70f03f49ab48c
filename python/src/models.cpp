// Models from Python: load a model file, predict one step of a trajectory, roll a trajectory out
// from its first frames. The network runs with the GIL released.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include "bindings.h"
#include "fignet/error.h"
#include "fignet/io/model_file.h"
#include "fignet/nn/gemm.h"
#include "fignet/rollout/rollout.h"
#include "fignet/train/training_config.h"

namespace fignet::python {

namespace {

using ModelHandle = std::shared_ptr<Model>;

// The model's fields of its training config (what `fignet train` records), as a dict.
py::dict config_of(const Model& model) {
  TrainingConfig config;
  config.model = model.config();
  const py::module_ json = py::module_::import("json");
  const py::dict all = json.attr("loads")(config.to_json());
  py::dict out;
  for (const std::string& name : TrainingConfig::field_names()) {
    if (TrainingConfig::is_model_field(name)) out[py::str(name)] = all[py::str(name)];
  }
  out["time_step"] = model.config().time_step;
  out["gravity"] = vec3_array(model.config().gravity);
  out["mesh_vertices"] = model.config().mesh_vertices;
  out["min_mass"] = model.config().min_mass;  // the training data's masses, kg (0: unknown)
  out["max_mass"] = model.config().max_mass;
  // The training data's materials: (lowest, highest), or None where the file does not record them.
  for (const auto& [name, range] : model.config().material_ranges()) {
    out[py::str(name)] =
        range->known() ? py::object(py::make_tuple(range->lowest, range->highest)) : py::none();
  }
  return out;
}

// The trajectory from frame `first` on (poses and velocities of later frames only).
Trajectory frames_from(const Trajectory& truth, int first) {
  Trajectory out = truth;
  for (TrajectoryObject& object : out.objects) {
    object.poses.erase(object.poses.begin(), object.poses.begin() + first);
    for (auto* v : {&object.linear_velocities, &object.angular_velocities}) {
      if (static_cast<int>(v->size()) > first) v->erase(v->begin(), v->begin() + first);
    }
  }
  return out;
}

Trajectory rollout_from(const ModelHandle& model, const Trajectory& truth,
                        std::optional<int> given_frames, std::optional<int> frames, int threads) {
  const int h = model->config().graph.history, total = truth.num_frames();
  const int given = given_frames.value_or(h + 1);
  if (given < h + 1 || given > total) {
    throw py::value_error(fmt::format(
        "given_frames = {}: the model needs at least history + 1 = {} and the trajectory has {} "
        "frames",
        given, h + 1, total));
  }
  const int end = frames ? *frames : total;
  if (end < given || end > total) {
    throw py::value_error(fmt::format(
        "frames = {}: must be in given_frames ({}) … the trajectory's {}", end, given, total));
  }
  truth.validate();
  py::gil_scoped_release release;
  ModelPredictor predictor(model, threads);
  // The rollout starts h + 1 frames before the first predicted one; earlier frames are the truth.
  const int start = given - h - 1;
  const Trajectory predicted = rollout(predictor, frames_from(truth, start), end - start);
  if (start == 0) return predicted;
  Trajectory out = truth;
  for (size_t o = 0; o < out.objects.size(); ++o) {
    std::vector<Pose>& poses = out.objects[o].poses;
    poses.resize(static_cast<size_t>(end));
    std::copy(predicted.objects[o].poses.begin() + h + 1, predicted.objects[o].poses.end(),
              poses.begin() + given);
    out.objects[o].linear_velocities.clear();
    out.objects[o].angular_velocities.clear();
  }
  return out;
}

py::dict predict_step(const ModelHandle& model, const Trajectory& truth, int frame, int threads) {
  const int h = model->config().graph.history;
  if (frame < h || frame + 1 >= truth.num_frames()) {
    throw py::value_error(fmt::format(
        "frame {}: a prediction needs the {} frames before it and a next frame (kinematic "
        "objects' next pose), so frame must be in {} … {}",
        frame, h, h, truth.num_frames() - 2));
  }
  truth.validate();
  StepWorkspace workspace;
  std::vector<Pose> next;
  {
    py::gil_scoped_release release;
    ModelPredictor predictor(model, threads);
    Scene scene;
    scene_at_frame(truth, frame, h, scene);
    predict_next_poses(predictor, scene, next, workspace);
  }
  py::dict out;
  out["accelerations"] = points_array(workspace.accelerations);
  out["positions"] = positions_array(next);
  out["quaternions"] = quaternions_array(next);
  return out;
}

}  // namespace

void bind_models(py::module_& m) {
  py::class_<Model, ModelHandle>(m, "Model",
                                 "A trained FIGNet model (immutable): its config, parameters and "
                                 "normaliser statistics, as `fignet train` writes them.")
      .def_property_readonly("config", &config_of,
                             "The model's fields of its training config, with the time step and "
                             "gravity of its training data.")
      .def_property_readonly("parameter_count",
                             [](const Model& model) { return model.parameters().size(); })
      .def_property_readonly(
          "time_step", [](const Model& model) { return model.config().time_step; },
          "Seconds per step, that of the training data; scenes and trajectories must match it.")
      .def_property_readonly(
          "gravity", [](const Model& model) { return vec3_array(model.config().gravity); },
          "Gravity of the training data, m/s² (3,).")
      .def_property_readonly(
          "history", [](const Model& model) { return model.config().graph.history; },
          "Past frames (velocities) each prediction needs besides the current one.")
      .def_property_readonly(
          "collision_radius",
          [](const Model& model) { return model.config().graph.collision_radius; },
          "Faces of different objects closer than this (metres) get face–face edges.")
      .def("predict", &predict_step, py::arg("trajectory"), py::arg("frame"),
           py::arg("threads") = 1,
           R"(One step from the truth: the model sees frames frame − history … frame and predicts
frame + 1. Returns a dict: "accelerations" (vertices of all objects, 3) as finite differences
x[t+1] − 2x[t] + x[t−1] in metres, and the next "positions" (objects, 3) and "quaternions"
(objects, 4) as (w, x, y, z) after the rigid fit.)")
      .def("__repr__", [](const Model& model) {
        const ModelConfig& config = model.config();
        // Hidden widths only where a grown model's differ from the latent width.
        std::string widths;
        if (config.mlp_hidden() != config.latent_size ||
            config.object_mlp_hidden() != config.latent_size)
          widths = fmt::format(", hidden {}, object hidden {}", config.mlp_hidden(),
                               config.object_mlp_hidden());
        return fmt::format(
            "<fignet.Model: preset {}, latent {}{}, {} message-passing steps, {} "
            "parameters, dt {:.6g} s>",
            config.preset, config.latent_size, widths, config.message_passing_steps,
            model.parameters().size(), config.time_step);
      });

  m.def(
      "load_model",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release release;
        return std::make_shared<Model>(load_model(path));
      },
      py::arg("path"),
      "Loads a model file (models/movi-a-small.h5, or what `fignet train` wrote).");
  m.def("rollout", &rollout_from, py::arg("model"), py::arg("trajectory"),
        py::arg("given_frames") = py::none(), py::arg("frames") = py::none(),
        py::arg("threads") = 1,
        R"(Rolls `trajectory` out with the network alone (as `fignet eval` does): its first
`given_frames` frames (default history + 1) are the truth, every later frame up to `frames`
(default all) is predicted from the model's own previous predictions. Kinematic objects follow
their recorded poses. Returns a Trajectory with the predicted poses.)");
  m.def(
      "set_bf16_products",
      [](bool on) {
        const GemmPrecision precision = on ? GemmPrecision::kBf16 : GemmPrecision::kF32;
        const std::string why_not = gemm_precision_unavailable(precision);
        if (!why_not.empty()) throw ConfigError("set_bf16_products: " + why_not);
        set_gemm_precision(precision);
      },
      py::arg("on") = true,
      R"(Runs every model's matrix products in bfloat16 from now on (False: back to float32), for the
whole process: rollouts, evaluations and scenes alike, as `fignet eval --bf16` does. Needs bf16
instructions (AVX512-BF16 or AMX); raises ConfigError saying why where they are missing.)");
  m.def(
      "bf16_products", [] { return gemm_precision() == GemmPrecision::kBf16; },
      "Whether the matrix products run in bfloat16 (set_bf16_products).");
}

}  // namespace fignet::python
