#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "../io/hdf5_time_stamps.h"
#include "../temp_folder.h"
#include "fignet/error.h"
#include "fignet/io/checkpoint.h"
#include "fignet/io/model_file.h"
#include "trajectory_fixtures.h"

namespace fignet {
namespace {

namespace fs = std::filesystem;

std::vector<Trajectory> falling_cubes() {
  const double dt = 1.0 / 48.0;
  Trajectory trajectory;
  trajectory.time_step = dt;
  trajectory.objects.push_back(testing::ballistic_object(
      testing::small_cube(), Vec3(0, 0, 2), Vec3(1, 0, 0), Vec3(0, 4, 2), 10, dt, Vec3(0, 0, -10)));
  trajectory.objects.push_back(testing::ballistic_object(testing::small_cube(0.3), Vec3(0, 0.8, 2),
                                                         Vec3(0, 1, 1), Vec3(-3, 0, 5), 10, dt,
                                                         Vec3(0, 0, -10)));
  return {trajectory};
}

ModelConfig tiny_model() {
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = 16;
  config.message_passing_steps = 2;
  config.noise_std = 1e-3;                  // so the restored generator state matters
  config.normalizer_max_accumulations = 6;  // freezes mid-run, after the checkpoint
  return config;
}

using Checkpoints = testing::TempFolderTest;

TEST_F(Checkpoints, ResumingContinuesBitForBit) {
  const auto data = falling_cubes();
  TrainerConfig trainer_config;
  trainer_config.batch_size = 2;
  trainer_config.seed = 7;
  trainer_config.adam.decay_steps = 20;
  trainer_config.adam.decay_start_step = 3;  // the resumed run's rate must decay from step 3
  trainer_config.rest_loss_weight = 30.0f;
  trainer_config.impact_loss_weight = 4.0f;
  trainer_config.still_air_fraction = 0.5f;
  trainer_config.pushforward_fraction = 0.5f;
  trainer_config.pushforward_skips_rest = true;
  trainer_config.pushforward_steps = 2;
  trainer_config.heading_consistency = 0.5f;
  Trainer uninterrupted(tiny_model(), trainer_config, data);
  uninterrupted.run(10, nullptr);

  Trainer first(tiny_model(), trainer_config, data);
  first.run(4, nullptr);
  save_checkpoint(first, dir_ / "run.ckpt.h5", 10);
  const Checkpoint checkpoint = load_checkpoint(dir_ / "run.ckpt.h5");
  EXPECT_EQ(checkpoint.state.step, 4);
  EXPECT_EQ(checkpoint.planned_steps, 10);
  EXPECT_EQ(checkpoint.trainer_config.batch_size, 2);
  EXPECT_EQ(checkpoint.trainer_config.adam.decay_steps, 20);
  EXPECT_EQ(checkpoint.trainer_config.adam.decay_start_step, 3);
  EXPECT_EQ(checkpoint.trainer_config.rest_loss_weight, 30.0f);
  EXPECT_EQ(checkpoint.trainer_config.impact_loss_weight, 4.0f);
  EXPECT_EQ(checkpoint.trainer_config.still_air_fraction, 0.5f);
  EXPECT_EQ(checkpoint.trainer_config.pushforward_fraction, 0.5f);
  EXPECT_TRUE(checkpoint.trainer_config.pushforward_skips_rest);
  EXPECT_EQ(checkpoint.trainer_config.pushforward_steps, 2);
  EXPECT_EQ(checkpoint.trainer_config.heading_consistency, 0.5f);
  Trainer resumed(checkpoint.model->config(), checkpoint.trainer_config, data,
                  checkpoint.model.get());
  resumed.restore(checkpoint.state);
  resumed.run(6, nullptr);

  EXPECT_EQ(testing::objects_with_time_stamps(dir_ / "run.ckpt.h5"), std::vector<std::string>{});
  EXPECT_EQ(resumed.steps_done(), 10);
  EXPECT_EQ(resumed.parameters(), uninterrupted.parameters());
  EXPECT_EQ(resumed.optimizer().second_moment(), uninterrupted.optimizer().second_moment());
  EXPECT_EQ(resumed.normalizers().target.mean(), uninterrupted.normalizers().target.mean());
}

// Fields added to checkpoints after their first files: a file without them reads as those runs
// trained (the trainer's defaults) and without a planned length.
TEST_F(Checkpoints, AFileWithoutLaterFieldsReadsWhatOlderRunsTrainedWith) {
  TrainerConfig trainer_config;
  trainer_config.gradient_clip = 0.5f;
  trainer_config.huber_delta = 2.0f;
  trainer_config.statistics_warmup = 3;
  trainer_config.rest_loss_weight = 30.0f;
  trainer_config.impact_loss_weight = 4.0f;
  trainer_config.still_air_fraction = 0.5f;
  trainer_config.weight_average = 0.75f;
  trainer_config.pushforward_fraction = 0.5f;
  trainer_config.pushforward_skips_rest = true;
  trainer_config.pushforward_steps = 3;
  trainer_config.heading_consistency = 0.5f;
  const auto data = falling_cubes();
  Trainer trainer(tiny_model(), trainer_config, data);
  const fs::path path = dir_ / "run.ckpt.h5";
  save_checkpoint(trainer, path, 10);
  {
    H5::H5File file(path.string(), H5F_ACC_RDWR);
    H5::Group training = file.openGroup("training");
    for (const char* name :
         {"gradient_clip", "huber_delta", "statistics_warmup", "rest_loss_weight",
          "impact_loss_weight", "weight_average", "still_air_fraction", "pushforward_fraction",
          "pushforward_skips_rest", "pushforward_steps", "heading_consistency", "planned_steps"}) {
      training.removeAttr(name);
    }
  }
  const Checkpoint checkpoint = load_checkpoint(path);
  const TrainerConfig defaults;
  EXPECT_EQ(checkpoint.trainer_config.gradient_clip, defaults.gradient_clip);
  EXPECT_EQ(checkpoint.trainer_config.huber_delta, defaults.huber_delta);
  EXPECT_EQ(checkpoint.trainer_config.statistics_warmup, defaults.statistics_warmup);
  EXPECT_EQ(checkpoint.trainer_config.rest_loss_weight, defaults.rest_loss_weight);
  EXPECT_EQ(checkpoint.trainer_config.impact_loss_weight, defaults.impact_loss_weight);
  EXPECT_EQ(checkpoint.trainer_config.weight_average, defaults.weight_average);
  EXPECT_EQ(checkpoint.trainer_config.still_air_fraction, defaults.still_air_fraction);
  EXPECT_EQ(checkpoint.trainer_config.pushforward_fraction, defaults.pushforward_fraction);
  EXPECT_EQ(checkpoint.trainer_config.pushforward_skips_rest, defaults.pushforward_skips_rest);
  EXPECT_EQ(checkpoint.trainer_config.pushforward_steps, defaults.pushforward_steps);
  EXPECT_EQ(checkpoint.trainer_config.heading_consistency, defaults.heading_consistency);
  EXPECT_EQ(checkpoint.planned_steps, 0);
}

// The parameters' moving average: what model() gives, kept in the checkpoint beside the
// parameters being optimised, resumed bit for bit, and started at a resume that turns it on.
TEST_F(Checkpoints, TheParameterAverageIsTheModelAndResumes) {
  const auto data = falling_cubes();
  TrainerConfig trainer_config;
  trainer_config.batch_size = 2;
  trainer_config.weight_average = 0.75f;
  Trainer uninterrupted(tiny_model(), trainer_config, data);
  // The average after each step, computed here in double from the parameters.
  std::vector<double> average(uninterrupted.parameters().begin(), uninterrupted.parameters().end());
  uninterrupted.run(8, [&](const TrainStep&) {
    const std::vector<float>& p = uninterrupted.parameters();
    for (size_t i = 0; i < p.size(); ++i) average[i] = 0.75 * average[i] + 0.25 * p[i];
    return true;
  });
  const std::vector<float> averaged = uninterrupted.model()->parameters();
  EXPECT_EQ(uninterrupted.current_model()->parameters(), uninterrupted.parameters());
  ASSERT_NE(averaged, uninterrupted.parameters());
  double worst = 0.0;
  for (size_t i = 0; i < averaged.size(); ++i) {
    worst = std::max(worst, std::abs(averaged[i] - average[i]) / (1e-3 + std::abs(average[i])));
  }
  EXPECT_LT(worst, 1e-5);

  Trainer first(tiny_model(), trainer_config, data);
  first.run(3, nullptr);
  save_checkpoint(first, dir_ / "run.ckpt.h5", 8);
  const Checkpoint checkpoint = load_checkpoint(dir_ / "run.ckpt.h5");
  EXPECT_EQ(checkpoint.trainer_config.weight_average, 0.75f);
  // The checkpoint's model is the parameters a resume continues from, not their average.
  EXPECT_EQ(checkpoint.model->parameters(), first.parameters());
  EXPECT_EQ(checkpoint.state.averaged_parameters, first.model()->parameters());
  Trainer resumed(checkpoint.model->config(), checkpoint.trainer_config, data,
                  checkpoint.model.get());
  resumed.restore(checkpoint.state);
  resumed.run(5, nullptr);
  EXPECT_EQ(resumed.parameters(), uninterrupted.parameters());
  EXPECT_EQ(resumed.model()->parameters(), averaged);

  // Turned on at a resume of a run without one: it starts at the resumed parameters.
  TrainerConfig plain = trainer_config;
  plain.weight_average = 0.0f;
  Trainer without(tiny_model(), plain, data);
  without.run(3, nullptr);
  EXPECT_EQ(without.model()->parameters(), without.parameters());
  save_checkpoint(without, dir_ / "plain.ckpt.h5");
  const Checkpoint no_average = load_checkpoint(dir_ / "plain.ckpt.h5");
  EXPECT_TRUE(no_average.state.averaged_parameters.empty());
  Trainer turned_on(no_average.model->config(), trainer_config, data, no_average.model.get());
  turned_on.restore(no_average.state);
  EXPECT_EQ(turned_on.model()->parameters(), without.parameters());
}

TEST_F(Checkpoints, AParameterAverageOutsideItsRangeIsRefused) {
  const auto data = falling_cubes();
  for (float decay : {-0.1f, 1.0f, std::nanf("")}) {
    TrainerConfig trainer_config;
    trainer_config.weight_average = decay;
    EXPECT_THROW(Trainer(tiny_model(), trainer_config, data), ConfigError) << decay;
  }
}

TEST_F(Checkpoints, LoadAsModelFilesButModelFilesDoNotResume) {
  const auto data = falling_cubes();
  Trainer trainer(tiny_model(), {}, data);
  trainer.run(2, nullptr);
  save_checkpoint(trainer, dir_ / "run.ckpt.h5");
  EXPECT_EQ(load_model(dir_ / "run.ckpt.h5").parameters(), trainer.parameters());
  save_model(*trainer.model(), dir_ / "model.h5");
  try {
    load_checkpoint(dir_ / "model.h5");
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("without training state"), std::string::npos) << e.what();
  }
}

TEST_F(Checkpoints, RestoreRejectsAStateOfAnotherSize) {
  const auto data = falling_cubes();
  Trainer trainer(tiny_model(), {}, data);
  TrainerState state = trainer.state();
  state.first_moment.pop_back();
  EXPECT_THROW(trainer.restore(state), ConfigError);
}

}  // namespace
}  // namespace fignet
