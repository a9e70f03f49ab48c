#include "report_html.h"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "report_player_js.h"  // generated: kReportPlayerJs, empty when not bundled

namespace fignet::cli {

namespace {

double rounded(double x, double scale = 1e4) {
  return std::round(x * scale) / scale;
}

nlohmann::json rounded_list(const std::vector<double>& values) {
  nlohmann::json out = nlohmann::json::array();
  for (double v : values) out.push_back(rounded(v));
  return out;
}

nlohmann::json scene_json(const bullet::SceneSpec& scene) {
  nlohmann::json objects = nlohmann::json::array();
  for (const bullet::BodySpec& body : scene.bodies) {
    const TriangleMesh& mesh = *body.mesh;
    std::vector<double> vertices(mesh.vertices().data(),
                                 mesh.vertices().data() + mesh.vertices().size());
    for (double& v : vertices) v = rounded(v);
    std::vector<int> faces(mesh.faces().data(), mesh.faces().data() + mesh.faces().size());
    objects.push_back({{"name", mesh.name()},
                       {"kinematic", body.kinematic},
                       {"vertices", vertices},
                       {"faces", faces}});
  }
  return {{"objects", objects},
          {"floor", scene.floor ? nlohmann::json(scene.floor->height) : nlohmann::json(nullptr)},
          {"frames", scene.frames},
          {"frame_step", scene.frame_step()}};
}

// Per scene: frames × objects × (x, y, z, qx, qy, qz, qw), flattened.
nlohmann::json poses_json(const bullet::RunResult& result) {
  nlohmann::json scenes = nlohmann::json::array();
  for (const Trajectory& t : result.trajectories) {
    std::vector<double> flat;
    for (int f = 0; f < t.num_frames(); ++f) {
      for (const TrajectoryObject& object : t.objects) {
        const Pose& p = object.poses[static_cast<size_t>(f)];
        for (double v : {p.position.x(), p.position.y(), p.position.z()})
          flat.push_back(rounded(v));
        const Eigen::Quaterniond& q = p.orientation;
        for (double v : {q.x(), q.y(), q.z(), q.w()}) flat.push_back(rounded(v));
      }
    }
    scenes.push_back(flat);
  }
  return scenes;
}

nlohmann::json report_json(const ReportInput& input, bool with_poses) {
  nlohmann::json runs = nlohmann::json::array();
  for (const bullet::RunResult& r : input.results) {
    nlohmann::json run = {{"name", r.run.name},
                          {"kind", r.run.kind},
                          {"ms_per_simulated_second", rounded(r.milliseconds_per_simulated_second)},
                          {"mean_translation_m", rounded(r.mean_translation, 1e6)},
                          {"final_translation_m", rounded(r.final_translation, 1e6)},
                          {"mean_rotation_deg", rounded(r.mean_rotation)},
                          {"final_rotation_deg", rounded(r.final_rotation)},
                          {"translation_per_frame_m", rounded_list(r.translation)},
                          {"rotation_per_frame_deg", rounded_list(r.rotation)},
                          {"per_trajectory", per_trajectory_json(r.errors)}};
    const size_t k = runs.size();
    if (k < input.against_reference.size() && input.against_reference[k]) {
      run["against_reference"] = scene_by_scene_json(*input.against_reference[k]);
      run["against_reference"]["reference"] = input.reference;
    }
    if (with_poses) run["poses"] = poses_json(r);
    runs.push_back(run);
  }
  nlohmann::json scenes = nlohmann::json::array();
  if (with_poses) {
    for (const bullet::SceneSpec& scene : input.scenes) scenes.push_back(scene_json(scene));
  }
  return {{"data", input.data},
          {"scene_count", input.scenes.size()},
          {"frame_step_s", input.scenes.front().frame_step()},
          {"runs", runs},
          {"scenes", scenes}};
}

std::string escape_html(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The speed–accuracy table, readable without JavaScript.
std::string table_html(const ReportInput& input) {
  std::string rows;
  for (size_t k = 0; k < input.results.size(); ++k) {
    const bullet::RunResult& r = input.results[k];
    const bool compared = k < input.against_reference.size() && input.against_reference[k];
    rows += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{:.2f}</td><td>{:.1f}</td><td>{:.4f}</td><td>{:.4f}</td>"
        "<td>{:.2f}</td><td>{:.2f}</td><td>{}</td><td>{}</td></tr>\n",
        escape_html(r.run.name), escape_html(r.run.kind), r.milliseconds_per_simulated_second,
        1000.0 / r.milliseconds_per_simulated_second, r.mean_translation, r.final_translation,
        r.mean_rotation, r.final_rotation,
        compared ? scene_by_scene_cell(input.against_reference[k]->translation) : "",
        compared ? scene_by_scene_cell(input.against_reference[k]->rotation) : "");
  }
  return fmt::format(
      "<table id=\"figures\"><thead><tr><th>run</th><th>kind</th><th>ms per simulated s</th>"
      "<th>× real time</th><th>translation mean (m)</th><th>translation last (m)</th>"
      "<th>rotation mean (°)</th><th>rotation last (°)</th><th>translation against {ref}, scene "
      "by scene</th><th>rotation against {ref}, scene by scene</th></tr></thead>\n<tbody>\n{rows}"
      "</tbody></table>\n<p class=\"note\">{legend}</p>\n",
      fmt::arg("ref", escape_html(input.reference)), fmt::arg("rows", rows),
      fmt::arg("legend", escape_html(scene_by_scene_legend())));
}

}  // namespace

bool report_player_bundled() {
  return !kReportPlayerJs.empty();
}

std::string render_report_json(const ReportInput& input) {
  return report_json(input, true).dump();
}

std::string render_report_html(const ReportInput& input) {
  std::string data = report_json(input, true).dump();
  // Inside <script>, "</" could end the element early; "<\/" is the same JSON string.
  for (size_t at = data.find("</"); at != std::string::npos; at = data.find("</", at + 3)) {
    data.replace(at, 2, "<\\/");
  }
  const std::string player =
      report_player_bundled()
          ? fmt::format("<script>\n{}\n</script>", kReportPlayerJs)
          : "<p class=\"note\">This build of fignet has no 3D player: three.js comes from npm "
            "(scripts/install-deps.sh installs it into web/node_modules), then rebuild.</p>";
  return fmt::format(R"(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>FIGNet vs native Bullet — {data}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 1.5em; color: #222; background: #fafafa; }}
table {{ border-collapse: collapse; margin: 1em 0; }}
th, td {{ border: 1px solid #ccc; padding: 0.3em 0.6em; text-align: right; }}
th:first-child, td:first-child, td:nth-child(2) {{ text-align: left; }}
.note {{ color: #666; max-width: 60em; }}
</style>
</head>
<body>
<h1>FIGNet vs native Bullet</h1>
<p class="note">{count} scenes from <code>{data}</code>, each started from the same first frame and
stepped by every run below. Errors are against native Bullet at 240 Hz; the chaos floor is how far
Bullet drifts from itself after a 1e-6 m nudge of the starting positions. Speed is wall-clock time
on the machine that wrote this report.</p>
{table}
<div id="app"></div>
<script type="application/json" id="report-data">{json}</script>
{player}
</body>
</html>
)",
                     fmt::arg("data", escape_html(input.data)),
                     fmt::arg("count", input.scenes.size()), fmt::arg("table", table_html(input)),
                     fmt::arg("json", data), fmt::arg("player", player));
}

}  // namespace fignet::cli
