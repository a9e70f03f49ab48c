// Training checkpoints: a model file (loadable by load_model) plus a /training group with the
// trainer's config and state, so `fignet train --resume` continues bit-for-bit where it stopped.
#pragma once

#include <filesystem>
#include <memory>

#include "fignet/train/trainer.h"

namespace fignet {

struct Checkpoint {
  std::shared_ptr<const Model> model;
  TrainerConfig trainer_config;
  TrainerState state;
};

// Written to a temporary file beside `path`, then renamed. Throws FileError.
void save_checkpoint(const Trainer& trainer, const std::filesystem::path& path);
// Throws FileError naming the file and the problem (also for a model file without /training).
Checkpoint load_checkpoint(const std::filesystem::path& path);

}  // namespace fignet
