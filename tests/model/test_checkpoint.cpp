#include <gtest/gtest.h>

#include <filesystem>

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
  trainer_config.rest_loss_weight = 30.0f;
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
  EXPECT_EQ(checkpoint.trainer_config.rest_loss_weight, 30.0f);
  Trainer resumed(checkpoint.model->config(), checkpoint.trainer_config, data,
                  checkpoint.model.get());
  resumed.restore(checkpoint.state);
  resumed.run(6, nullptr);

  EXPECT_EQ(resumed.steps_done(), 10);
  EXPECT_EQ(resumed.parameters(), uninterrupted.parameters());
  EXPECT_EQ(resumed.optimizer().second_moment(), uninterrupted.optimizer().second_moment());
  EXPECT_EQ(resumed.normalizers().target.mean(), uninterrupted.normalizers().target.mean());
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
