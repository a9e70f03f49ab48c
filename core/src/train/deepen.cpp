#include "fignet/train/deepen.h"

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

DeepenedRun deepen(const Model& model, const TrainerState& state, int added_steps,
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

  const size_t trained_size = model.parameters().size();
  for (const auto* moments :
       {&state.first_moment, &state.second_moment, &state.averaged_parameters}) {
    if (!moments->empty() && moments->size() != trained_size) {
      throw ConfigError(
          fmt::format("deepen: the training state has {} entries where the model has {} parameters",
                      moments->size(), trained_size));
    }
  }

  // A fresh model of the deeper config: its layout, and the new steps' initial weights.
  const Model fresh(config);
  std::vector<float> params = fresh.parameters();
  DeepenedRun run{nullptr, state};
  const auto resized = [&](const std::vector<float>& trained) {
    return trained.empty() ? std::vector<float>() : std::vector<float>(params.size(), 0.0f);
  };
  run.state.first_moment = resized(state.first_moment);
  run.state.second_moment = resized(state.second_moment);
  run.state.averaged_parameters = resized(state.averaged_parameters);

  std::unordered_map<std::string, const TensorInfo*> trained_tensors;
  for (const TensorInfo& t : model.network().layout().tensors()) trained_tensors[t.name] = &t;
  for (const TensorInfo& t : fresh.network().layout().tensors()) {
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
    const auto found = trained_tensors.find(trained_name);
    if (found == trained_tensors.end() || found->second->rows != t.rows ||
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
  run.model = std::make_shared<const Model>(config, std::move(params), model.normalizers());
  return run;
}

}  // namespace fignet
