// `fignet compare`: the side-by-side with native Bullet. The scenes of a trajectory file are
// stepped by native Bullet at 240 Hz (ground truth), FIGNetDynamicsWorld with each model, coarser
// native Bullet and the 1e-6 m chaos floor; a speed–accuracy table on the terminal, and a
// self-contained HTML report with a 3D player, error plots and the speed–accuracy chart.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <optional>

#include "commands.h"
#include "device_option.h"
#include "fignet/bullet/comparison.h"
#include "fignet/error.h"
#include "fignet/io/model_file.h"
#include "fignet/io/trajectory_file.h"
#include "progress.h"
#include "report_html.h"
#include "scene_by_scene.h"
#include "text_file.h"

namespace fignet::cli {

namespace {

namespace fs = std::filesystem;

struct CompareArgs {
  std::vector<fs::path> models;
  fs::path data, report = "fignet-report.html", json;
  int max_scenes = 5, frames = -1, threads = 1, turns = 1;
  bool mirror = false, bf16 = false;
};

void print_table(const std::vector<bullet::RunResult>& results) {
  // The run column fits the longest name (a model's file name, its options, the run's kind).
  std::vector<std::string> names;
  size_t width = 48;
  for (const bullet::RunResult& r : results) {
    names.push_back(fmt::format("{} ({})", r.run.name, r.run.kind));
    width = std::max(width, names.back().size());
  }
  fmt::print("\n{:<{}} {:>12} {:>9} {:>19} {:>19}\n", "", width, "speed", "", "translation (m)",
             "rotation (deg)");
  fmt::print("{:<{}} {:>12} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "run", width, "ms/sim s", "x real",
             "mean", "last", "mean", "last");
  for (size_t k = 0; k < results.size(); ++k) {
    const bullet::RunResult& r = results[k];
    const double realtime = 1000.0 / r.milliseconds_per_simulated_second;
    fmt::print("{:<{}} {:>12.2f} {:>9.1f} {:>9.4f} {:>9.4f} {:>9.2f} {:>9.2f}\n", names[k], width,
               r.milliseconds_per_simulated_second, realtime, r.mean_translation,
               r.final_translation, r.mean_rotation, r.final_rotation);
  }
  fmt::print(
      "\nErrors against the ground truth, every run started from the same first frame; x real: "
      "simulated seconds per wall-clock second on this machine. The chaos floor is how far "
      "Bullet drifts from itself after a 1e-6 m nudge: no simulator can be asked to beat it.\n");
}

// The runs against Bullet at the model's own step, scene by scene: the cheap native setting a
// learned simulator has to beat (index-aligned with results; none for the ground truth and it).
std::vector<std::optional<SceneBySceneRow>> against_coarse_bullet(
    const std::vector<bullet::RunResult>& results, const std::string& reference) {
  std::vector<std::optional<SceneBySceneRow>> rows(results.size());
  const auto found = std::find_if(results.begin(), results.end(), [&](const bullet::RunResult& r) {
    return r.run.name == reference;
  });
  if (found == results.end() || results.front().errors.size() < 2) return rows;
  for (size_t k = 1; k < results.size(); ++k) {
    if (&results[k] == &*found) continue;
    rows[k] = compare_scene_by_scene(found->errors, results[k].errors, found->run.name,
                                     results[k].run.name);
  }
  return rows;
}

void print_against(const std::vector<bullet::RunResult>& results, const std::string& reference,
                   const std::vector<std::optional<SceneBySceneRow>>& rows) {
  std::vector<std::string> labels;
  std::vector<const SceneBySceneRow*> lines;
  for (size_t k = 0; k < rows.size(); ++k) {
    if (!rows[k]) continue;
    labels.push_back(fmt::format("{} ({})", results[k].run.name, results[k].run.kind));
    lines.push_back(&*rows[k]);
  }
  if (!lines.empty()) print_scene_by_scene(reference, labels, lines, 48);
}

void run_compare(const CompareArgs& args) {
  use_bf16_products(args.bf16);
  std::vector<Trajectory> recorded = read_trajectories(args.data);
  if (static_cast<int>(recorded.size()) > args.max_scenes) recorded.resize(args.max_scenes);
  std::vector<bullet::SceneSpec> scenes;
  for (const Trajectory& t : recorded) {
    scenes.push_back(bullet::scene_from_trajectory(t));
    if (args.frames > 0) scenes.back().frames = std::min(scenes.back().frames, args.frames);
  }
  std::vector<std::shared_ptr<const Model>> models;
  std::vector<std::string> names;
  for (const fs::path& file : args.models) {
    models.push_back(std::make_shared<const Model>(load_model(file)));
    names.push_back(file.filename().string() + (args.bf16 ? ", bf16 products" : ""));
    const double step = models.back()->config().time_step;
    if (std::abs(step - scenes[0].frame_step()) > 1e-9) {
      throw ConfigError(
          fmt::format("--model '{}': trained with steps of {} s, the scenes' frames are {} s",
                      file.string(), step, scenes[0].frame_step()));
    }
  }
  std::vector<bullet::ComparisonRun> runs = bullet::standard_runs(models, names);
  for (bullet::ComparisonRun& run : runs) {
    run.world_options.threads = args.threads;
    run.world_options.turns = args.turns;
    run.world_options.mirror = args.mirror;
  }
  ProgressBar progress("compare", static_cast<long long>(runs.size() * scenes.size()));
  const std::vector<bullet::RunResult> results =
      bullet::compare_runs(scenes, runs, [&](int run, int scene) {
        progress.update(
            static_cast<long long>(run) * static_cast<long long>(scenes.size()) + scene + 1,
            runs[static_cast<size_t>(run)].name);
      });
  progress.finish(static_cast<long long>(runs.size() * scenes.size()));
  fmt::print("{} scenes from {}, {} frames of {:.4f} s\n", scenes.size(), args.data.string(),
             scenes[0].frames, scenes[0].frame_step());
  print_table(results);
  const std::string reference = bullet::kCoarseBulletRun;
  const std::vector<std::optional<SceneBySceneRow>> against =
      against_coarse_bullet(results, reference);
  print_against(results, reference, against);

  const ReportInput input{args.data.string(), scenes, results, reference, against};
  write_text_atomically(args.report, render_report_html(input));
  fmt::print("report: {}\n", fs::absolute(args.report).string());
  if (!args.json.empty()) {
    write_text_atomically(args.json, render_report_json(input) + "\n");
    fmt::print("results: {}\n", args.json.string());
  }
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  auto* cmd = app.add_subcommand(
      "compare",
      "Step the same scenes with native Bullet (240 Hz ground truth, 48 Hz, 2 solver "
      "iterations, a 1e-6 m perturbed start) and FIGNet; print a speed-accuracy table and "
      "write a self-contained HTML report");
  cmd->add_option("--model", args->models, "Model file (repeat to compare several)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--data", args->data,
                  "Trajectory file whose scenes (first frames) are simulated, e.g. from "
                  "`fignet generate`")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--report", args->report, "HTML report to write")->capture_default_str();
  cmd->add_option("--json", args->json, "Also write the figures and trajectories as JSON");
  cmd->add_option("--max-scenes", args->max_scenes, "Use the first N scenes of the file")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--frames", args->frames, "Simulate N frames (default: the file's)")
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--threads", args->threads,
                  "Threads for the network's matrix products, or with --turns for the turned "
                  "copies, one per thread (0: every core; more than one helps large scenes and "
                  "--turns on an otherwise idle machine)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--turns", args->turns,
                  "Average each prediction over the scene turned by k/turns of a turn about the "
                  "vertical (FIGNetWorldOptions::turns; turns times the network's cost)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  add_bf16_option(*cmd, args->bf16);
  cmd->add_flag("--mirror", args->mirror,
                "Average with the scene seen in a mirror too, at each turn (FIGNetWorldOptions::"
                "mirror; twice --turns' cost)");
  cmd->callback([args] { run_compare(*args); });
}

}  // namespace fignet::cli
