// Two runs over the same scenes set against each other scene by scene, as `fignet eval` sets each
// model against the first and `fignet compare` each run against Bullet at the model's step.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "fignet/rollout/metrics.h"
#include "fignet/rollout/paired_comparison.h"

namespace fignet::cli {

// A run against the reference on mean translation and rotation. A run whose rollouts left the
// finite numbers (or a reference with no error at all) has no comparison: `why_not` says why.
struct SceneBySceneRow {
  std::optional<PairedComparison> translation, rotation;
  std::string why_not;
};

// reference[i] and run[i] are the errors of scene i.
SceneBySceneRow compare_scene_by_scene(const std::vector<RolloutErrors>& reference,
                                       const std::vector<RolloutErrors>& run,
                                       const std::string& reference_name,
                                       const std::string& run_name);

// "+3.1% [-2.0, +8.4] 61/100 p=0.035", or "-" without a comparison.
std::string scene_by_scene_cell(const std::optional<PairedComparison>& comparison);
// What the cells mean, for the end of a printed table.
std::string scene_by_scene_legend();
nlohmann::json scene_by_scene_json(const std::optional<PairedComparison>& comparison);
// {"mean_translation": ..., "mean_rotation": ...} of a row.
nlohmann::json scene_by_scene_json(const SceneBySceneRow& row);

// Each scene's figures, as `fignet eval --json` and `fignet compare --json` write them under a
// run's "per_trajectory" (scripts/paired-evals.py pairs two such lists across files).
nlohmann::json per_trajectory_json(const std::vector<RolloutErrors>& errors);

// The section a command prints: "against REFERENCE, scene by scene", one line per labelled row
// (labels padded to label_width), then the legend.
void print_scene_by_scene(const std::string& reference, const std::vector<std::string>& labels,
                          const std::vector<const SceneBySceneRow*>& rows, int label_width);

}  // namespace fignet::cli
