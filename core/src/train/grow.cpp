#include "fignet/train/grow.h"

#include <fmt/format.h>

#include <string>
#include <unordered_map>

#include "fignet/error.h"

namespace fignet {

namespace {

constexpr std::string_view kProcessor = "processor/";

// "processor/<k>/<rest>" as (k, rest); (-1, name) for tensors outside the processor.
std::pair<int, std::string> split_step(const std::string& name) {
  if (!name.starts_with(kProcessor)) return {-1, name};
  const size_t slash = name.find('/', kProcessor.size());
  return {std::stoi(name.substr(kProcessor.size(), slash - kProcessor.size())),
          name.substr(slash + 1)};
}

// Throws unless each of the state's moments and average is empty or one value per parameter.
void check_state_fits(const char* what, const TrainerState& state, size_t parameters) {
  for (const auto* moments :
       {&state.first_moment, &state.second_moment, &state.averaged_parameters}) {
    if (!moments->empty() && moments->size() != parameters) {
      throw ConfigError(
          fmt::format("{}: the training state has {} entries where the model has {} parameters",
                      what, moments->size(), parameters));
    }
  }
}

// What growing `model` into `config` starts from: a fresh model of the grown config (its layout,
// and the initial values of whatever is new), the grown run with the trained state's step and
// counters and its moments and average zero-filled (or empty where the trained state's are), and
// the trained tensors by name.
struct Growth {
  Model fresh;
  std::vector<float> params;
  GrownRun run;
  std::unordered_map<std::string, const TensorInfo*> trained_tensors;

  Growth(const char* what, const Model& model, const TrainerState& state, const ModelConfig& config)
      : fresh(config), params(fresh.parameters()), run{nullptr, state} {
    check_state_fits(what, state, model.parameters().size());
    const auto resized = [&](const std::vector<float>& trained) {
      return trained.empty() ? std::vector<float>() : std::vector<float>(params.size(), 0.0f);
    };
    run.state.first_moment = resized(state.first_moment);
    run.state.second_moment = resized(state.second_moment);
    run.state.averaged_parameters = resized(state.averaged_parameters);
    for (const TensorInfo& t : model.network().layout().tensors()) trained_tensors[t.name] = &t;
  }

  // The grown model, with the trained model's normalisers.
  GrownRun finish(const Model& model) {
    run.model =
        std::make_shared<const Model>(fresh.config(), std::move(params), model.normalizers());
    return std::move(run);
  }
};

}  // namespace

std::vector<int> deepened_step_sources(int trained, int added) {
  if (trained < 1) {
    throw ConfigError(fmt::format(
        "deepen: the model has {} message-passing steps; new steps go after trained ones",
        trained));
  }
  if (added < 1)
    throw ConfigError(fmt::format("deepen: {} steps to add (must be at least 1)", added));
  std::vector<int> sources;
  for (int k = 0; k < trained; ++k) {
    sources.push_back(k);
    // Trained step k is followed by the new steps whose even share falls to it.
    const int after = (k + 1) * added / trained - k * added / trained;
    sources.insert(sources.end(), after, -1);
  }
  return sources;
}

GrownRun deepen(const Model& model, const TrainerState& state, int added_steps,
                float new_step_scale) {
  if (!(new_step_scale >= 0.0f && new_step_scale <= 1.0f)) {
    throw ConfigError(
        fmt::format("deepen: new steps' LayerNorm scale {} (must be in 0..1)", new_step_scale));
  }
  const ModelConfig& trained_config = model.config();
  const std::vector<int> sources =
      deepened_step_sources(trained_config.message_passing_steps, added_steps);
  ModelConfig config = trained_config;
  config.message_passing_steps = static_cast<int>(sources.size());
  config.validate();

  // New steps' weights are drawn as a fresh model of the deeper config would draw them.
  Growth growth("deepen", model, state, config);
  std::vector<float>& params = growth.params;
  GrownRun& run = growth.run;
  for (const TensorInfo& t : growth.fresh.network().layout().tensors()) {
    const auto [step, rest] = split_step(t.name);
    const int source = step < 0 ? -1 : sources[step];
    float* const begin = params.data() + t.offset;
    if (step >= 0 && source < 0) {
      // A new step: LayerNorm's output zero (the identity through the residual) or a fraction of
      // a normalised update.
      if (rest.ends_with("/layer_norm/scale")) std::fill(begin, begin + t.size(), new_step_scale);
      if (!run.state.averaged_parameters.empty()) {
        std::copy(begin, begin + t.size(), run.state.averaged_parameters.begin() + t.offset);
      }
      continue;  // moments stay zero
    }
    const std::string trained_name =
        step < 0 ? t.name : std::string(kProcessor) + std::to_string(source) + "/" + rest;
    const auto found = growth.trained_tensors.find(trained_name);
    if (found == growth.trained_tensors.end() || found->second->rows != t.rows ||
        found->second->cols != t.cols) {
      throw ConfigError(
          fmt::format("deepen: tensor '{}' has no counterpart '{}' of {}x{} in the "
                      "trained model",
                      t.name, trained_name, t.rows, t.cols));
    }
    const size_t from = found->second->offset, count = t.size();
    auto copy = [&](const std::vector<float>& in, std::vector<float>& out) {
      if (!in.empty()) std::copy_n(in.begin() + from, count, out.begin() + t.offset);
    };
    copy(model.parameters(), params);
    copy(state.first_moment, run.state.first_moment);
    copy(state.second_moment, run.state.second_moment);
    copy(state.averaged_parameters, run.state.averaged_parameters);
  }
  return growth.finish(model);
}

GrownRun widen(const Model& model, const TrainerState& state, int hidden_size,
               int object_hidden_size) {
  const ModelConfig& trained_config = model.config();
  ModelConfig config = trained_config;
  if (hidden_size > 0) config.hidden_size = hidden_size;
  if (object_hidden_size > 0) config.object_hidden_size = object_hidden_size;
  config.validate();
  const auto refuse_narrower = [](const char* field, int wider, int trained) {
    if (wider < trained) {
      throw ConfigError(fmt::format("widen: {} {} is narrower than the trained network's {}", field,
                                    wider, trained));
    }
  };
  refuse_narrower("hidden width", config.mlp_hidden(), trained_config.mlp_hidden());
  refuse_narrower("object-node hidden width", config.object_mlp_hidden(),
                  trained_config.object_mlp_hidden());
  if (config.mlp_hidden() == trained_config.mlp_hidden() &&
      config.object_mlp_hidden() == trained_config.object_mlp_hidden()) {
    throw ConfigError(
        fmt::format("widen: nothing grows (hidden width {}, object-node hidden width {} already)",
                    config.mlp_hidden(), config.object_mlp_hidden()));
  }
  // New units' incoming weights are drawn as a fresh model of the wider config would draw them.
  Growth growth("widen", model, state, config);
  std::vector<float>& params = growth.params;
  GrownRun& run = growth.run;
  for (const TensorInfo& t : growth.fresh.network().layout().tensors()) {
    const auto found = growth.trained_tensors.find(t.name);
    if (found == growth.trained_tensors.end() || found->second->rows > t.rows ||
        found->second->cols > t.cols) {
      throw ConfigError(
          fmt::format("widen: tensor '{}' ({}x{}) has no counterpart within it in "
                      "the trained model",
                      t.name, t.rows, t.cols));
    }
    const TensorInfo& old = *found->second;
    // The trained tensor fills the top-left block. Rows beyond it multiply new hidden units:
    // zero, so that they change no output. Columns beyond it in the trained rows feed new
    // hidden units: the fresh model's values (incoming weights drawn, biases zero).
    float* const begin = params.data() + t.offset;
    for (int r = old.rows; r < t.rows; ++r) std::fill_n(begin + r * t.cols, t.cols, 0.0f);
    auto copy = [&](const std::vector<float>& in, std::vector<float>& out) {
      if (in.empty()) return;
      for (int r = 0; r < old.rows; ++r) {
        std::copy_n(in.begin() + old.offset + static_cast<size_t>(r) * old.cols, old.cols,
                    out.begin() + t.offset + static_cast<size_t>(r) * t.cols);
      }
    };
    if (!run.state.averaged_parameters.empty()) {
      std::copy_n(begin, t.size(), run.state.averaged_parameters.begin() + t.offset);
    }
    copy(model.parameters(), params);
    copy(state.first_moment, run.state.first_moment);  // new weights' moments stay zero
    copy(state.second_moment, run.state.second_moment);
    copy(state.averaged_parameters, run.state.averaged_parameters);
  }
  return growth.finish(model);
}

}  // namespace fignet
