#include "scene_by_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

#include "fignet/error.h"

namespace fignet::cli {

namespace {

std::vector<double> field_of(const std::vector<RolloutErrors>& errors,
                             double RolloutErrors::*field) {
  std::vector<double> values;
  values.reserve(errors.size());
  for (const RolloutErrors& e : errors) values.push_back(e.*field);
  return values;
}

}  // namespace

SceneBySceneRow compare_scene_by_scene(const std::vector<RolloutErrors>& reference,
                                       const std::vector<RolloutErrors>& run,
                                       const std::string& reference_name,
                                       const std::string& run_name) {
  SceneBySceneRow row;
  PairedComparisonOptions options;
  options.a_name = reference_name;
  options.b_name = run_name;
  try {
    row.translation = compare_paired(field_of(reference, &RolloutErrors::mean_translation),
                                     field_of(run, &RolloutErrors::mean_translation), options);
    row.rotation = compare_paired(field_of(reference, &RolloutErrors::mean_rotation),
                                  field_of(run, &RolloutErrors::mean_rotation), options);
  } catch (const ConfigError& e) {
    row = {std::nullopt, std::nullopt, e.what()};
  }
  return row;
}

std::string scene_by_scene_cell(const std::optional<PairedComparison>& c) {
  if (!c) return "-";
  return fmt::format("{:+.1f}% [{:+.1f}, {:+.1f}] {}/{} p={:.2g}", 100 * c->relative,
                     100 * c->relative_low, 100 * c->relative_high, c->b_lower,
                     c->b_lower + c->a_lower, c->sign_test_p);
}

std::string scene_by_scene_legend() {
  const PairedComparisonOptions options;
  return fmt::format(
      "per cent: the run's mean error over the reference's, minus one; [..]: {:.0f} % interval of "
      "it over {} bootstrap resamples of the scenes (each drawn with both runs' errors); k/n: "
      "the scenes where the run's error is the lower, of those not tied; p: two-sided sign test "
      "of that count. An interval that holds 0 does not tell the two apart on these scenes.",
      100 * options.confidence, options.resamples);
}

nlohmann::json scene_by_scene_json(const std::optional<PairedComparison>& c) {
  if (!c) return nullptr;
  return {{"relative", c->relative},
          {"relative_low_95", c->relative_low},
          {"relative_high_95", c->relative_high},
          {"lower_scenes", c->b_lower},
          {"higher_scenes", c->a_lower},
          {"sign_test_p", c->sign_test_p}};
}

nlohmann::json scene_by_scene_json(const SceneBySceneRow& row) {
  return {{"mean_translation", scene_by_scene_json(row.translation)},
          {"mean_rotation", scene_by_scene_json(row.rotation)}};
}

void print_scene_by_scene(const std::string& reference, const std::vector<std::string>& labels,
                          const std::vector<const SceneBySceneRow*>& rows, int label_width) {
  // Columns as wide as their widest entry, so long labels and tiny p-values keep them aligned.
  std::vector<std::string> translation, rotation;
  size_t cell_width = 38;
  for (const SceneBySceneRow* row : rows) {
    translation.push_back(scene_by_scene_cell(row->translation));
    rotation.push_back(scene_by_scene_cell(row->rotation));
    cell_width = std::max({cell_width, translation.back().size(), rotation.back().size()});
  }
  size_t label_columns = static_cast<size_t>(std::max(label_width, 3));
  for (const std::string& label : labels) label_columns = std::max(label_columns, label.size());
  fmt::print("\nagainst {}, scene by scene\n", reference);
  fmt::print("{:<{}} {:>{}} {:>{}}\n", "run", label_columns, "mean translation", cell_width,
             "mean rotation", cell_width);
  for (size_t k = 0; k < rows.size(); ++k) {
    fmt::print("{:<{}} {:>{}} {:>{}}{}\n", labels[k], label_columns, translation[k], cell_width,
               rotation[k], cell_width, rows[k]->why_not.empty() ? "" : "  " + rows[k]->why_not);
  }
  fmt::print("\n{}\n", scene_by_scene_legend());
}

nlohmann::json per_trajectory_json(const std::vector<RolloutErrors>& errors) {
  nlohmann::json out = nlohmann::json::array();
  for (const RolloutErrors& t : errors) {
    out.push_back({{"mean_translation_m", t.mean_translation},
                   {"final_translation_m", t.final_translation},
                   {"mean_rotation_deg", t.mean_rotation},
                   {"final_rotation_deg", t.final_rotation},
                   {"predicted_travel_m", t.predicted_travel},
                   {"true_travel_m", t.true_travel}});
  }
  return out;
}

}  // namespace fignet::cli
