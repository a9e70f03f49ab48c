#include <gtest/gtest.h>

#include <limits>

#include "../error_text.h"
#include "fignet/data/trajectory.h"
#include "fignet/error.h"
#include "fignet/rollout/predictor.h"
#include "fignet/train/grow.h"
#include "trajectory_fixtures.h"

namespace fignet {
namespace {

// Two cubes 5 cm apart, 5 cm above the floor: face-face edges between them and with the floor.
std::vector<Trajectory> cubes_in_contact() {
  const double dt = 1.0 / 48.0;
  Trajectory trajectory;
  trajectory.time_step = dt;
  trajectory.objects.push_back(testing::ballistic_object(testing::small_cube(), Vec3(0, 0, 0.25),
                                                         Vec3(0.2, 0, 0), Vec3(0, 1, 0), 8, dt,
                                                         Vec3::Zero()));
  trajectory.objects.push_back(testing::ballistic_object(testing::small_cube(), Vec3(0, 0.45, 0.25),
                                                         Vec3(0, -0.1, 0), Vec3(1, 0, 0), 8, dt,
                                                         Vec3::Zero()));
  return {trajectory};
}

ModelConfig tiny_model(int steps) {
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = 16;
  config.message_passing_steps = steps;
  return config;
}

Points predict(std::shared_ptr<const Model> model, const Trajectory& trajectory) {
  ModelPredictor predictor(std::move(model));
  Scene scene;
  scene_at_frame(trajectory, 4, predictor.history(), scene);
  Points accelerations;
  predictor.predict(scene, accelerations);
  return accelerations;
}

size_t offset_of(const Model& model, const std::string& name) {
  for (const TensorInfo& t : model.network().layout().tensors()) {
    if (t.name == name) return t.offset;
  }
  ADD_FAILURE() << "no tensor " << name;
  return 0;
}

TEST(Deepen, NewStepsAreSpreadEvenlyAfterTrainedOnes) {
  EXPECT_EQ(deepened_step_sources(5, 5), (std::vector<int>{0, -1, 1, -1, 2, -1, 3, -1, 4, -1}));
  EXPECT_EQ(deepened_step_sources(5, 1), (std::vector<int>{0, 1, 2, 3, 4, -1}));
  EXPECT_EQ(deepened_step_sources(5, 2), (std::vector<int>{0, 1, 2, -1, 3, 4, -1}));
  EXPECT_EQ(deepened_step_sources(2, 5), (std::vector<int>{0, -1, -1, 1, -1, -1, -1}));
  EXPECT_NE(
      testing::error_of<ConfigError>([] { deepened_step_sources(5, 0); }).find("0 steps to add"),
      std::string::npos);
  EXPECT_NE(testing::error_of<ConfigError>([] {
              deepened_step_sources(0, 2);
            }).find("has 0 message-passing steps"),
            std::string::npos);
}

// A trained run deepened: the same predictions (from the parameters and from their average), the
// optimizer's state carried to the tensors it belongs to, and training goes on into the new
// steps.
TEST(Deepen, TheDeeperNetworkPredictsWhatTheTrainedOneDidAndTrainsOn) {
  const auto data = cubes_in_contact();
  TrainerConfig trainer_config;
  trainer_config.batch_size = 2;
  trainer_config.statistics_warmup = 0;
  trainer_config.weight_average = 0.5f;
  Trainer trainer(tiny_model(2), trainer_config, data);
  trainer.run(3, nullptr);
  const auto trained = trainer.current_model();
  const TrainerState state = trainer.state();

  const GrownRun deeper = deepen(*trained, state, 3);
  const Model& model = *deeper.model;
  ASSERT_EQ(model.config().message_passing_steps, 5);  // 0, new, 1, new, new
  EXPECT_EQ(deeper.state.step, 3);
  const Points before = predict(trained, data[0]);
  ASSERT_GT(before.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(predict(deeper.model, data[0]), before);
  // The average is the model a run writes: deepened alike.
  const auto average = [](const Model& m, const std::vector<float>& params) {
    return std::make_shared<const Model>(m.config(), params, m.normalizers());
  };
  EXPECT_EQ(predict(average(model, deeper.state.averaged_parameters), data[0]),
            predict(average(*trained, state.averaged_parameters), data[0]));

  // Trained step 1 is step 2 now, with its moments; step 1 is new: LayerNorm at zero, no moments.
  const std::string w = "/mesh_node/linear_0/w";
  const size_t from = offset_of(*trained, "processor/1" + w),
               to = offset_of(model, "processor/2" + w);
  EXPECT_EQ(model.parameters()[to + 7], trained->parameters()[from + 7]);
  EXPECT_EQ(deeper.state.second_moment[to + 7], state.second_moment[from + 7]);
  EXPECT_NE(deeper.state.second_moment[to + 7], 0.0f);
  for (const char* tensor :
       {"processor/1/mesh_node/layer_norm/scale", "processor/4/face_edge/layer_norm/scale",
        "processor/3/object_node/layer_norm/offset"}) {
    const size_t at = offset_of(model, tensor);
    EXPECT_EQ(model.parameters()[at], 0.0f) << tensor;
    EXPECT_EQ(deeper.state.first_moment[at], 0.0f) << tensor;
    EXPECT_EQ(deeper.state.averaged_parameters[at], 0.0f) << tensor;
  }
  const size_t new_weight = offset_of(model, "processor/1" + w);
  EXPECT_NE(model.parameters()[new_weight], 0.0f);  // drawn as a new model's

  // Training goes on: the new steps' LayerNorm scales move first.
  Trainer resumed(model.config(), trainer_config, data, deeper.model.get());
  resumed.restore(deeper.state);
  resumed.run(2, nullptr);
  EXPECT_EQ(resumed.steps_done(), 5);
  const size_t scale = offset_of(model, "processor/1/mesh_node/layer_norm/scale");
  EXPECT_NE(resumed.parameters()[scale], 0.0f);
}

// A small starting scale: the new steps add that fraction of a normalised update, so the
// predictions move a little, and the scales start there.
TEST(Deepen, NewStepsMayStartWithASmallScale) {
  const auto data = cubes_in_contact();
  const auto trained = std::make_shared<const Model>(tiny_model(2));
  const GrownRun identity = deepen(*trained, TrainerState{}, 2);
  const GrownRun scaled = deepen(*trained, TrainerState{}, 2, 0.25f);
  EXPECT_EQ(scaled.model
                ->parameters()[offset_of(*scaled.model, "processor/1/mesh_node/layer_norm/scale")],
            0.25f);
  const Points before = predict(trained, data[0]);
  EXPECT_EQ(predict(identity.model, data[0]), before);
  const Points after = predict(scaled.model, data[0]);
  EXPECT_GT((after - before).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(scaled.state.first_moment.empty());  // a model without a run: no moments to carry
  for (float bad : {-0.1f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
    EXPECT_NE(testing::error_of<ConfigError>([&] {
                deepen(*trained, TrainerState{}, 2, bad);
              }).find("must be in 0..1"),
              std::string::npos)
        << bad;
  }
}

TEST(Deepen, AStateOfAnotherModelIsRefused) {
  const Model model(tiny_model(2));
  TrainerState state;
  state.first_moment.assign(model.parameters().size() + 1, 0.0f);
  state.second_moment = state.first_moment;
  EXPECT_NE(testing::error_of<ConfigError>([&] {
              deepen(model, state, 1);
            }).find("has " + std::to_string(model.parameters().size() + 1) + " entries"),
            std::string::npos);
  EXPECT_NE(testing::error_of<ConfigError>([&] {
              deepen(model, TrainerState{}, 70);
            }).find("message_passing_steps"),
            std::string::npos);
}

const TensorInfo& tensor_named(const Model& model, const std::string& name) {
  for (const TensorInfo& t : model.network().layout().tensors()) {
    if (t.name == name) return t;
  }
  throw std::runtime_error("no tensor " + name);
}

// Largest difference between two predictions relative to the larger one's largest entry: a wider
// product may sum in another order, so equal up to float rounding, not bit for bit.
double relative_difference(const Points& a, const Points& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(a.cwiseAbs().maxCoeff(), 1e-30);
}

// A trained run widened: the same predictions to float rounding (parameters and average), the
// trained weights and their moments in the top-left of the wider tensors, new units' outgoing
// weights zero and their incoming ones drawn, and training moves the outgoing ones.
TEST(Widen, TheWiderNetworkPredictsWhatTheTrainedOneDidAndTrainsOn) {
  const auto data = cubes_in_contact();
  TrainerConfig trainer_config;
  trainer_config.batch_size = 2;
  trainer_config.statistics_warmup = 0;
  trainer_config.weight_average = 0.5f;
  Trainer trainer(tiny_model(2), trainer_config, data);  // latent and hidden width 16
  trainer.run(3, nullptr);
  const auto trained = trainer.current_model();
  const TrainerState state = trainer.state();

  const GrownRun wider = widen(*trained, state, 24, 40);
  const Model& model = *wider.model;
  ASSERT_EQ(model.config().mlp_hidden(), 24);
  ASSERT_EQ(model.config().object_mlp_hidden(), 40);
  EXPECT_EQ(model.config().latent_size, 16);
  EXPECT_EQ(wider.state.step, 3);
  const Points before = predict(trained, data[0]);
  ASSERT_GT(before.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(relative_difference(predict(wider.model, data[0]), before), 1e-5);
  const auto average = [](const Model& m, const std::vector<float>& params) {
    return std::make_shared<const Model>(m.config(), params, m.normalizers());
  };
  EXPECT_LT(relative_difference(predict(average(model, wider.state.averaged_parameters), data[0]),
                                predict(average(*trained, state.averaged_parameters), data[0])),
            1e-5);

  // Each tensor: the trained block top-left with its moments; beyond it, new rows (outgoing
  // weights of new units) zero, new columns in trained rows (incoming weights) drawn or zero.
  for (const char* name : {"processor/1/mesh_edge/linear_0/w", "processor/1/mesh_edge/linear_1/w",
                           "processor/0/object_node/linear_1/w", "decoder/mesh_node/linear_2/w",
                           "processor/0/face_edge/linear_1/b"}) {
    const TensorInfo& t = tensor_named(model, name);
    const TensorInfo& old = tensor_named(*trained, name);
    ASSERT_TRUE(t.rows > old.rows || t.cols > old.cols) << name;
    bool drawn = false;
    for (int r = 0; r < t.rows; ++r) {
      for (int c = 0; c < t.cols; ++c) {
        const size_t at = t.offset + static_cast<size_t>(r) * t.cols + c;
        if (r < old.rows && c < old.cols) {
          const size_t from = old.offset + static_cast<size_t>(r) * old.cols + c;
          ASSERT_EQ(model.parameters()[at], trained->parameters()[from]) << name;
          ASSERT_EQ(wider.state.first_moment[at], state.first_moment[from]) << name;
          ASSERT_EQ(wider.state.second_moment[at], state.second_moment[from]) << name;
          ASSERT_EQ(wider.state.averaged_parameters[at], state.averaged_parameters[from]) << name;
        } else {
          if (r >= old.rows) {
            ASSERT_EQ(model.parameters()[at], 0.0f) << name;
          }
          drawn = drawn || model.parameters()[at] != 0.0f;
          ASSERT_EQ(wider.state.second_moment[at], 0.0f) << name;
          ASSERT_EQ(wider.state.averaged_parameters[at], model.parameters()[at]) << name;
        }
      }
    }
    EXPECT_EQ(drawn, std::string(name).ends_with("/w") && t.cols > old.cols) << name;
  }

  // Training goes on: new units' outgoing weights move at the first steps.
  Trainer resumed(model.config(), trainer_config, data, wider.model.get());
  resumed.restore(wider.state);
  resumed.run(2, nullptr);
  EXPECT_EQ(resumed.steps_done(), 5);
  const TensorInfo& out = tensor_named(model, "processor/1/mesh_node/linear_2/w");
  const float* last_row = resumed.parameters().data() + out.offset + (out.rows - 1) * out.cols;
  EXPECT_GT(Eigen::Map<const Eigen::VectorXf>(last_row, out.cols).cwiseAbs().maxCoeff(), 0.0f);
}

TEST(Widen, ObjectNodesAloneAndRefusals) {
  const auto data = cubes_in_contact();
  const auto trained = std::make_shared<const Model>(tiny_model(2));
  const GrownRun objects = widen(*trained, TrainerState{}, 0, 64);
  EXPECT_EQ(objects.model->config().mlp_hidden(), 16);
  EXPECT_EQ(objects.model->config().object_mlp_hidden(), 64);
  EXPECT_EQ(tensor_named(*objects.model, "processor/1/mesh_node/linear_1/w").rows, 16);
  EXPECT_EQ(tensor_named(*objects.model, "processor/1/object_node/linear_1/w").rows, 64);
  EXPECT_EQ(tensor_named(*objects.model, "encoder/object_node/linear_0/w").cols, 64);
  EXPECT_LT(relative_difference(predict(objects.model, data[0]), predict(trained, data[0])), 1e-5);
  EXPECT_TRUE(objects.state.first_moment.empty());

  // Widening the others after the object-node MLPs leaves those as they are.
  const GrownRun both = widen(*objects.model, TrainerState{}, 32, 0);
  EXPECT_EQ(both.model->config().mlp_hidden(), 32);
  EXPECT_EQ(both.model->config().object_mlp_hidden(), 64);

  const auto error = [&](const Model& m, int hidden, int object_hidden) {
    return testing::error_of<ConfigError>([&] { widen(m, TrainerState{}, hidden, object_hidden); });
  };
  EXPECT_NE(error(*objects.model, 0, 32)
                .find("object-node hidden width 32 is narrower than the "
                      "trained network's 64"),
            std::string::npos);
  EXPECT_NE(error(*trained, 8, 0).find("hidden width 8 is narrower than the trained network's 16"),
            std::string::npos);
  EXPECT_NE(error(*trained, 16, 0).find("nothing grows"), std::string::npos);
  EXPECT_NE(error(*trained, 5000, 0).find("hidden_size = 5000"), std::string::npos);
  TrainerState state;
  state.first_moment.assign(trained->parameters().size() - 1, 0.0f);
  EXPECT_NE(testing::error_of<ConfigError>([&] {
              widen(*trained, state, 32, 0);
            }).find("widen: the training state has"),
            std::string::npos);
}

}  // namespace
}  // namespace fignet
