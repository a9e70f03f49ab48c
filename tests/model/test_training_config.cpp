#include <gtest/gtest.h>

#include "../error_text.h"
#include "fignet/error.h"
#include "fignet/train/training_config.h"

namespace fignet {
namespace {

// Only ConfigErrors count here: another error type would be the wrong report.
std::string error_of(const std::function<void()>& f) {
  return testing::error_of<ConfigError>(f);
}

TEST(TrainingConfig, JsonRoundTripKeepsEveryField) {
  TrainingConfig config = TrainingConfig::preset_named("small");
  config.model.latent_size = 48;
  config.model.graph.collision_radius = 0.07;
  config.model.graph.floor = FloorModel::kImplicit;
  config.model.graph.collisions = CollisionEdges::kNodeNode;
  config.trainer.adam.learning_rate_start = 5e-4f;
  config.trainer.batch_size = 3;
  config.steps = 1234;
  TrainingConfig copy = TrainingConfig::preset_named("paper");
  copy.apply_json(config.to_json(), "test");
  EXPECT_EQ(copy.to_json(), config.to_json());
  EXPECT_EQ(copy.model.latent_size, 48);
  EXPECT_EQ(copy.model.graph.floor, FloorModel::kImplicit);
  EXPECT_EQ(copy.trainer.adam.learning_rate_start, 5e-4f);
  EXPECT_NE(config.to_json().find("\"learning_rate_start\": 0.0005,"), std::string::npos);
}

TEST(TrainingConfig, SettingsOverrideOneFieldAndAPresetResetsTheModel) {
  TrainingConfig config = TrainingConfig::preset_named("paper");
  config.apply_setting("latent_size=32");
  config.apply_setting("floor=none");
  config.apply_setting("object_nodes=false");
  EXPECT_EQ(config.model.latent_size, 32);
  EXPECT_EQ(config.model.graph.floor, FloorModel::kNone);
  EXPECT_FALSE(config.model.graph.object_nodes);
  config.apply_setting("preset=small");
  EXPECT_EQ(config.model.latent_size, 64);
  EXPECT_EQ(config.model.message_passing_steps, 5);
}

// The presets train with the study's recipe; the structs' defaults stay the first recipe's, which
// is how a file without one of these fields reads.
TEST(TrainingConfig, PresetsCarryTheRecipeAndTheDefaultsStayTheOldOne) {
  for (const char* name : {"small", "paper"}) {
    const TrainingConfig preset = TrainingConfig::preset_named(name);
    TrainingConfig old;
    old.model = ModelConfig::preset_named(name);
    old.trainer.adam.decay_steps = old.steps;
    EXPECT_EQ(
        old.differing_fields(preset),
        (std::vector<std::string>{"static_internal_edges", "log_mass", "velocity_log_scale",
                                  "noise", "normalizer_max_accumulations", "batch_size",
                                  "learning_rate_start", "learning_rate_end", "gradient_clip",
                                  "huber_delta", "rest_loss_weight", "still_air_fraction",
                                  "weight_average", "pushforward_fraction", "statistics_warmup"}))
        << name;
    EXPECT_EQ(preset.field_text("noise"), "\"rigid\"");
    EXPECT_EQ(preset.trainer.batch_size, 8);
    EXPECT_EQ(preset.trainer.weight_average, 0.999f);
    EXPECT_EQ(preset.model.graph.velocity_log_scale, 1e-4);
    EXPECT_EQ(preset.trainer.rest_loss_weight, 100.0f);
    EXPECT_EQ(preset.trainer.still_air_fraction, 0.1f);
    EXPECT_EQ(preset.trainer.adam.learning_rate_start, 5e-4f);
    EXPECT_EQ(preset.trainer.adam.learning_rate_end, 5e-5f);
    EXPECT_EQ(preset.trainer.pushforward_fraction, 0.5f);
    EXPECT_EQ(old.trainer.pushforward_fraction, 0.0f);
    EXPECT_EQ(old.trainer.adam.learning_rate_start, 1e-3f);
    EXPECT_EQ(old.trainer.still_air_fraction, 0.0f);
    EXPECT_EQ(old.trainer.batch_size, 4);
    EXPECT_EQ(old.model.noise, NoiseKind::kVertex);
  }
}

TEST(TrainingConfig, BadInputNamesTheField) {
  TrainingConfig config;
  EXPECT_NE(
      error_of([&] { config.apply_setting("latent=3"); }).find("unknown config field 'latent'"),
      std::string::npos);
  EXPECT_NE(error_of([&] { config.apply_setting("floor=wood"); }).find("'wood' is not one of"),
            std::string::npos);
  EXPECT_NE(error_of([&] { config.apply_setting("steps"); }).find("expected key=value"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              config.apply_json("{\"history\": \"two\"}", "f.json");
            }).find("f.json: 'history' = \"two\" has the wrong type"),
            std::string::npos);
  EXPECT_NE(error_of([&] { config.apply_json("[1, 2", "f.json"); }).find("f.json: not valid JSON"),
            std::string::npos);
  config.trainer.batch_size = 0;
  EXPECT_NE(error_of([&] { config.validate(); }).find("batch_size = 0"), std::string::npos);
  config.trainer.batch_size = 4;
  config.apply_setting("noise_correction=1.5");
  EXPECT_NE(error_of([&] { config.validate(); }).find("noise_correction = 1.5 (must be in [0, 1])"),
            std::string::npos);
  config.apply_setting("noise_correction=0.5");
  config.model.min_mass = 2.0;  // the training masses are both known or both unknown (0)
  EXPECT_NE(error_of([&] { config.validate(); }).find("max_mass = 0 (must be >= min_mass)"),
            std::string::npos);
  config.model.max_mass = 3.0;
  EXPECT_NO_THROW(config.validate());
  config.model.friction = {-0.1, 0.5};
  EXPECT_NE(error_of([&] { config.validate(); }).find("friction range [-0.1, 0.5]"),
            std::string::npos);
  config.model.friction = {};
  EXPECT_NO_THROW(config.validate());
  config.apply_setting("decay_start_step=-1");
  EXPECT_NE(error_of([&] { config.validate(); }).find("decay_start_step = -1 (must be >= 0)"),
            std::string::npos);
  config.apply_setting("decay_start_step=0");
  config.apply_setting("pushforward_steps=9");
  EXPECT_NE(error_of([&] { config.validate(); }).find("pushforward_steps = 9 (must be in 1..8"),
            std::string::npos);
  config.apply_setting("pushforward_steps=1");
  config.apply_setting("impact_loss_weight=-2");
  EXPECT_NE(error_of([&] { config.validate(); }).find("impact_loss_weight = -2 (must be >= 0"),
            std::string::npos);
  config.apply_setting("impact_loss_weight=4");
  EXPECT_NO_THROW(config.validate());
}

TEST(DataRange, WidensToHoldEachValueAndHoldsEverythingWhileUnknown) {
  DataRange range;
  EXPECT_FALSE(range.known());
  EXPECT_TRUE(range.holds(-5.0));
  range.add(0.8);
  EXPECT_TRUE(range.known());
  EXPECT_TRUE(range.holds(0.8));
  EXPECT_FALSE(range.holds(0.4));
  range.add(0.4);
  EXPECT_EQ(range.lowest, 0.4);
  EXPECT_EQ(range.highest, 0.8);
  EXPECT_TRUE(range.holds(0.6));
  // A value that went through a float32 file or Bullet's btScalar is still the data's.
  EXPECT_TRUE(range.holds(static_cast<float>(0.4)));
  EXPECT_TRUE(range.holds(static_cast<float>(0.8)));
  EXPECT_FALSE(range.holds(0.39));
  EXPECT_FALSE(range.holds(0.81));
}

// What messages print of a range: stress's materials line and the Python scene's warning.
TEST(DataRange, TextIsOneValueARangeOrUnknown) {
  DataRange range;
  EXPECT_EQ(range.text(), "unknown");
  range.add(0.3);
  EXPECT_EQ(range.text(), "0.3");
  range.add(0.7);
  EXPECT_EQ(range.text(), "0.3-0.7");
}

// fignet train lets decay_steps follow --steps unless a --set or --config named it.
TEST(TrainingConfig, RemembersWhetherDecayStepsWasGiven) {
  TrainingConfig config = TrainingConfig::preset_named("small");
  config.apply_json("{\"batch_size\": 8, \"steps\": 100}", "f.json");
  config.apply_setting("latent_size=32");
  EXPECT_FALSE(config.decay_steps_given);
  config.apply_setting("decay_steps=50");
  EXPECT_TRUE(config.decay_steps_given);
  EXPECT_EQ(config.trainer.adam.decay_steps, 50);
  TrainingConfig from_file = TrainingConfig::preset_named("small");
  from_file.apply_json("{\"decay_steps\": 70}", "f.json");
  EXPECT_TRUE(from_file.decay_steps_given);
}

}  // namespace
}  // namespace fignet
