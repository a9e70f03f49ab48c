// The `fignet compare` report: one self-contained HTML file (figures as a table, the data as
// JSON, and the three.js player bundled at build time) that opens from disk with no network.
#pragma once

#include <string>
#include <vector>

#include "fignet/bullet/comparison.h"
#include "scene_by_scene.h"

namespace fignet::cli {

struct ReportInput {
  std::string data;  // where the scenes came from
  const std::vector<bullet::SceneSpec>& scenes;
  const std::vector<bullet::RunResult>& results;
  // Each run against the reference run, scene by scene (index-aligned with results; none for the
  // ground truth and the reference itself).
  std::string reference;
  std::vector<std::optional<SceneBySceneRow>> against_reference;
};

// Figures, per-frame errors, meshes and every run's poses, numbers rounded for size.
std::string render_report_json(const ReportInput& input);
std::string render_report_html(const ReportInput& input);
// Whether this build bundled the 3D player (three.js from npm, see web/).
bool report_player_bundled();

}  // namespace fignet::cli
