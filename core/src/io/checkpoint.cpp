#include "fignet/io/checkpoint.h"

#include <fmt/format.h>

#include "fignet/error.h"
#include "hdf5_util.h"
#include "model_contents.h"

namespace fignet {

namespace {

constexpr const char* kWhat = "checkpoint";

void write_training(H5::Group group, const TrainerConfig& config, const TrainerState& state) {
  using hdf5::write_attribute;
  write_attribute(group, "batch_size", static_cast<long long>(config.batch_size));
  write_attribute(group, "seed", static_cast<long long>(config.seed));
  write_attribute(group, "learning_rate_start", double{config.adam.learning_rate_start});
  write_attribute(group, "learning_rate_end", double{config.adam.learning_rate_end});
  write_attribute(group, "decay_steps", static_cast<long long>(config.adam.decay_steps));
  write_attribute(group, "decay_start_step", static_cast<long long>(config.adam.decay_start_step));
  write_attribute(group, "gradient_clip", double{config.gradient_clip});
  write_attribute(group, "huber_delta", double{config.huber_delta});
  write_attribute(group, "statistics_warmup", static_cast<long long>(config.statistics_warmup));
  write_attribute(group, "rest_loss_weight", double{config.rest_loss_weight});
  write_attribute(group, "impact_loss_weight", double{config.impact_loss_weight});
  write_attribute(group, "weight_average", double{config.weight_average});
  write_attribute(group, "still_air_fraction", double{config.still_air_fraction});
  write_attribute(group, "pushforward_fraction", double{config.pushforward_fraction});
  write_attribute(group, "pushforward_skips_rest",
                  static_cast<long long>(config.pushforward_skips_rest ? 1 : 0));
  write_attribute(group, "pushforward_steps", static_cast<long long>(config.pushforward_steps));
  write_attribute(group, "heading_consistency", double{config.heading_consistency});
  write_attribute(group, "step", static_cast<long long>(state.step));
  write_attribute(group, "rng", state.rng);
  const hsize_t n = state.first_moment.size();
  hdf5::write_floats(group, "adam_first_moment", state.first_moment.data(), {n});
  hdf5::write_floats(group, "adam_second_moment", state.second_moment.data(), {n});
  if (!state.averaged_parameters.empty()) {
    hdf5::write_floats(group, "averaged_parameters", state.averaged_parameters.data(), {n});
  }
}

void read_training(const H5::Group& group, size_t parameters, const std::string& where,
                   TrainerConfig& config, TrainerState& state) {
  using namespace hdf5;
  config.batch_size = static_cast<int>(read_integer(group, "batch_size"));
  config.seed = static_cast<std::uint64_t>(read_integer(group, "seed"));
  config.adam.learning_rate_start = static_cast<float>(read_double(group, "learning_rate_start"));
  config.adam.learning_rate_end = static_cast<float>(read_double(group, "learning_rate_end"));
  config.adam.decay_steps = read_integer(group, "decay_steps");
  // Added later: absent in older checkpoints, which trained without them (the defaults).
  auto read_float_or = [&](const char* name, float absent) {
    return static_cast<float>(read_double_or(group, name, absent));
  };
  config.adam.decay_start_step =
      read_integer_or(group, "decay_start_step", config.adam.decay_start_step);
  config.gradient_clip = read_float_or("gradient_clip", config.gradient_clip);
  config.huber_delta = read_float_or("huber_delta", config.huber_delta);
  config.statistics_warmup =
      static_cast<int>(read_integer_or(group, "statistics_warmup", config.statistics_warmup));
  config.rest_loss_weight = read_float_or("rest_loss_weight", config.rest_loss_weight);
  config.impact_loss_weight = read_float_or("impact_loss_weight", config.impact_loss_weight);
  config.weight_average = read_float_or("weight_average", config.weight_average);
  config.still_air_fraction = read_float_or("still_air_fraction", config.still_air_fraction);
  config.pushforward_fraction = read_float_or("pushforward_fraction", config.pushforward_fraction);
  config.pushforward_skips_rest =
      read_integer_or(group, "pushforward_skips_rest", config.pushforward_skips_rest ? 1 : 0) != 0;
  config.pushforward_steps =
      static_cast<int>(read_integer_or(group, "pushforward_steps", config.pushforward_steps));
  config.heading_consistency = read_float_or("heading_consistency", config.heading_consistency);
  state.step = read_integer(group, "step");
  state.rng = read_string(group, "rng");
  for (auto [name, out] : {std::pair("adam_first_moment", &state.first_moment),
                           std::pair("adam_second_moment", &state.second_moment),
                           std::pair("averaged_parameters", &state.averaged_parameters)}) {
    if (out == &state.averaged_parameters && !exists(group, name)) continue;  // a run without
    const H5::DataSet dataset = group.openDataSet(name);
    if (shape_of(dataset, where) != std::vector<hsize_t>{parameters}) {
      throw FileError(
          fmt::format("{}: 'training/{}' does not have {} entries", where, name, parameters));
    }
    out->resize(parameters);
    read_floats(dataset, out->data());
  }
}

}  // namespace

void save_checkpoint(const Trainer& trainer, const std::filesystem::path& path,
                     std::int64_t planned_steps) {
  // The parameters being optimised, which a resume continues from; the average is in the state.
  const auto model = trainer.current_model();
  const TrainerState state = trainer.state();
  hdf5::write_atomically(path, kWhat, [&](H5::H5File& file) {
    write_model_contents(file, *model);
    H5::Group training = hdf5::create_group(file, "training");
    write_training(training, trainer.trainer_config(), state);
    hdf5::write_attribute(training, "planned_steps", static_cast<long long>(planned_steps));
  });
}

Checkpoint load_checkpoint(const std::filesystem::path& path) {
  const H5::H5File file = hdf5::open_for_reading(path, kWhat);
  const std::string where = fmt::format("{} '{}'", kWhat, path.string());
  auto model = std::make_shared<const Model>(read_model_contents(file, where));
  if (!hdf5::exists(file.openGroup("/"), "training")) {
    throw FileError(
        fmt::format("{}: a model file without training state (no /training group); "
                    "start a new run from it instead of resuming",
                    where));
  }
  TrainerConfig config;
  TrainerState state;
  std::int64_t planned_steps = 0;
  try {
    const H5::Group training = file.openGroup("training");
    read_training(training, model->parameters().size(), where, config, state);
    // Absent from checkpoints written before it was recorded.
    planned_steps = hdf5::read_integer_or(training, "planned_steps", 0);
  } catch (const H5::Exception& e) {
    throw FileError(fmt::format("{}: cannot read 'training' ({})", where, e.getDetailMsg()));
  }
  return {std::move(model), config, std::move(state), planned_steps};
}

}  // namespace fignet
