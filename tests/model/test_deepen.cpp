#include <gtest/gtest.h>

#include <limits>

#include "../error_text.h"
#include "fignet/data/trajectory.h"
#include "fignet/error.h"
#include "fignet/rollout/predictor.h"
#include "fignet/train/deepen.h"
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

  const DeepenedRun deeper = deepen(*trained, state, 3);
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
  const DeepenedRun identity = deepen(*trained, TrainerState{}, 2);
  const DeepenedRun scaled = deepen(*trained, TrainerState{}, 2, 0.25f);
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

}  // namespace
}  // namespace fignet
