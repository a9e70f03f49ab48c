// What `fignet train` runs: the model, the trainer and the run length in one flat set of named
// fields, read from JSON and overridable one field at a time ("latent_size=64").
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fignet/model/config.h"
#include "fignet/train/trainer.h"

namespace fignet {

struct TrainingConfig {
  ModelConfig model;
  TrainerConfig trainer;
  std::int64_t steps = 1'000'000;  // total optimisation steps of the run
  // Whether apply_json or apply_setting named decay_steps: otherwise a run's learning rate
  // decays over its own length (fignet train sets decay_steps to steps). Not a saved field.
  bool decay_steps_given = false;

  // The model preset ("paper" or "small") trained with the recipe of docs/training-study.md:
  // batch 8, the parameters' moving average (0.999) as the model, rigid-body noise, log mass,
  // velocities also as logarithms (velocity_log_scale 1e-4), no edges inside static bodies,
  // normalisers frozen after 800 warm-up batches, gradients clipped to norm 1, Huber loss beyond
  // 3σ. A default-constructed TrainingConfig keeps the first recipe (batch 4, vertex noise, ...),
  // which is what checkpoint and model files without these fields were trained with.
  static TrainingConfig preset_named(std::string_view name);

  // Field names in documentation order (also the JSON keys).
  static const std::vector<std::string>& field_names();
  // One flat JSON object of every field.
  std::string to_json() const;
  // Sets the fields present in a JSON object; `where` names the source in errors. Unknown keys
  // and wrongly typed values throw ConfigError naming the key.
  void apply_json(std::string_view json, const std::string& where);
  // Sets one field from "key=value" (value in JSON syntax; bare words are strings).
  void apply_setting(std::string_view setting);
  // Whether the field belongs to the model (its architecture, graph, noise, normalisers), which a
  // resumed run cannot change; the others are the trainer's (loss, optimizer, sampling) and the
  // run's length.
  static bool is_model_field(std::string_view name);
  // Whether a resumed run may change the field (--set on --resume): the trainer's fields, the
  // training noise (noise_std, noise, noise_correction) and random_yaw, which shape the samples
  // but not the parameters or the normalisers.
  static bool changes_on_resume(std::string_view name);
  // The fields whose values differ from `other`'s, in documentation order.
  std::vector<std::string> differing_fields(const TrainingConfig& other) const;
  // One field's value as JSON text ("0.001", "\"face\""); ConfigError for an unknown name.
  std::string field_text(std::string_view name) const;
  // Throws ConfigError naming the first invalid field.
  void validate() const;
};

}  // namespace fignet
