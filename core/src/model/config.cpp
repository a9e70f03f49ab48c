#include "fignet/model/config.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "fignet/error.h"

namespace fignet {

void DataRange::add(double value) {
  lowest = known() ? std::min(lowest, value) : value;
  highest = known() ? std::max(highest, value) : value;
}

bool DataRange::holds(double value) const {
  // Trajectory files store properties as float32: a value that went through one is not
  // outside the range it came from.
  const double slack = 1e-6 * std::max(1.0, std::max(std::abs(lowest), std::abs(highest)));
  return !known() || (value >= lowest - slack && value <= highest + slack);
}

std::string DataRange::text() const {
  if (!known()) return "unknown";
  return lowest == highest ? fmt::format("{:.3g}", lowest)
                           : fmt::format("{:.3g}-{:.3g}", lowest, highest);
}

const std::vector<std::string>& ModelConfig::preset_names() {
  static const std::vector<std::string> names = {"paper", "small"};
  return names;
}

ModelConfig ModelConfig::preset_named(std::string_view name) {
  ModelConfig config;
  config.preset = std::string(name);
  if (name == "paper") return config;
  if (name == "small") {
    config.latent_size = 64;
    config.message_passing_steps = 5;
    return config;
  }
  throw ConfigError(fmt::format("unknown model preset '{}'; known presets: {}", name,
                                fmt::join(preset_names(), ", ")));
}

void ModelConfig::validate() const {
  graph.validate();
  auto fail = [](const char* field, auto value, const char* rule) {
    throw ConfigError(fmt::format("model config: {} = {} ({})", field, value, rule));
  };
  if (latent_size < 1 || latent_size > 4096) fail("latent_size", latent_size, "must be in 1..4096");
  if (hidden_size < 0 || hidden_size > 4096) fail("hidden_size", hidden_size, "must be in 0..4096");
  if (object_hidden_size < 0 || object_hidden_size > 4096) {
    fail("object_hidden_size", object_hidden_size, "must be in 0..4096");
  }
  if (message_passing_steps < 0 || message_passing_steps > 64) {
    fail("message_passing_steps", message_passing_steps, "must be in 0..64");
  }
  if (!(noise_std >= 0.0) || !std::isfinite(noise_std))
    fail("noise_std", noise_std, "must be >= 0");
  if (!(noise_correction >= 0.0 && noise_correction <= 1.0))
    fail("noise_correction", noise_correction, "must be in [0, 1]");
  if (normalizer_max_accumulations < 1) {
    fail("normalizer_max_accumulations", normalizer_max_accumulations, "must be >= 1");
  }
  if (mesh_vertices < 0) fail("mesh_vertices", mesh_vertices, "must be >= 0");
  if (!(min_mass >= 0.0) || !std::isfinite(min_mass)) fail("min_mass", min_mass, "must be >= 0");
  if (!(max_mass >= min_mass) || !std::isfinite(max_mass)) {
    fail("max_mass", max_mass, "must be >= min_mass");
  }
  if ((min_mass == 0.0) != (max_mass == 0.0)) {
    fail("min_mass", min_mass, "and max_mass must both be 0 (unknown) or both be > 0");
  }
  for (const auto& [name, range] : material_ranges()) {
    if (range->known() && !(range->lowest >= 0.0 && std::isfinite(range->highest))) {
      throw ConfigError(fmt::format("model config: {} range [{}, {}] (must be finite and >= 0)",
                                    name, range->lowest, range->highest));
    }
  }
  if (!(time_step > 0.0) || !std::isfinite(time_step)) fail("time_step", time_step, "must be > 0");
  if (!gravity.allFinite()) fail("gravity", "non-finite", "must be finite");
}

}  // namespace fignet
