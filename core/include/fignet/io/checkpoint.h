// Training checkpoints: a model file (loadable by load_model) plus a /training group with the
// trainer's config and state, so `fignet train --resume` continues bit-for-bit where it stopped.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>

#include "fignet/train/trainer.h"

namespace fignet {

struct Checkpoint {
  std::shared_ptr<const Model> model;
  TrainerConfig trainer_config;
  TrainerState state;
  std::int64_t planned_steps = 0;  // the run's total length (0: not recorded)
};

// Written to a temporary file beside `path`, then renamed; `planned_steps` is the run's total
// length, so a resumed run stops where the original would have. Throws FileError.
void save_checkpoint(const Trainer& trainer, const std::filesystem::path& path,
                     std::int64_t planned_steps = 0);
// Throws FileError naming the file and the problem (also for a model file without /training).
Checkpoint load_checkpoint(const std::filesystem::path& path);

}  // namespace fignet
