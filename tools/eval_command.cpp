// `fignet eval`: rollouts of one or more models over a test split, next to the ballistic
// baseline: errors per frame, over the rollout and at its end, penetration against the ground
// truth, face–face edges and milliseconds per step; a table on the terminal, JSON for scripts.
#include <fmt/format.h>

#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.h"
#include "device_option.h"
#include "fignet/error.h"
#include "fignet/io/model_file.h"
#include "fignet/io/trajectory_file.h"
#include "fignet/rollout/evaluation.h"
#include "fignet/rollout/one_step.h"
#include "process_group.h"
#include "progress.h"
#include "scene_by_scene.h"
#include "text_file.h"

namespace fignet::cli {

namespace {

namespace fs = std::filesystem;

struct EvalArgs {
  std::vector<fs::path> models, data;
  fs::path json;
  int frames = -1, max_trajectories = -1, threads = 1, turns = 1;
  bool free_flight = false, mirror = false, bf16 = false;
  bool baseline = true, penetration = true, regimes = true;
};

struct Row {
  std::string name, kind;
  Evaluation result;
  std::optional<OneStepTotals> one_step;  // with --regimes (the default)
};

// What the regime split needs from the (first) model: its graph and its target's scale.
struct RegimeSetting {
  GraphConfig graph;
  Vec3 target_std = Vec3::Ones();
};

// One-step errors by regime over this process's trajectories, summed over every process on
// process 0.
OneStepTotals one_step_by_regime(const std::string& name, AccelerationPredictor& predictor,
                                 const std::vector<Trajectory>& test,
                                 const RegimeSetting& setting) {
  const ProcessGroup& group = process_group();
  ProgressBar progress(fmt::format("one-step {}", name), static_cast<long long>(test.size()));
  OneStepOptions options;
  if (group.is_root()) options.on_trajectory = [&](int done) { progress.update(done); };
  const OneStepTotals mine =
      one_step_totals(predictor, setting.graph, setting.target_std, test, options);
  if (group.is_root()) progress.finish(static_cast<long long>(test.size()));
  const std::vector<double> gathered = group.collective->gather(mine.serialize());
  if (!group.is_root()) return mine;
  const size_t size = mine.serialize().size();
  OneStepTotals all;
  for (size_t at = 0; at + size <= gathered.size(); at += size) {
    all += OneStepTotals::deserialize(std::span(gathered).subspan(at, size));
  }
  return all;
}

std::string kind_of(const ModelConfig& config) {
  return config.graph.collisions == CollisionEdges::kFaceFace ? "FIGNet" : "FIGNet-NoFaceCollision";
}

// Every trajectory of the files, up to `max` (all when < 0), checked to share one time step;
// under mpirun, this process's share of them.
std::vector<Trajectory> read_test_split(const EvalArgs& args) {
  std::vector<Trajectory> all = read_trajectories(args.data);
  if (all.empty()) throw ConfigError("--data: the files hold no trajectory");
  if (args.max_trajectories >= 0 && static_cast<int>(all.size()) > args.max_trajectories) {
    all.resize(static_cast<size_t>(args.max_trajectories));
  }
  if (static_cast<int>(all.size()) < process_group().size()) {
    throw ConfigError(fmt::format("--data: {} trajectories for {} processes", all.size(),
                                  process_group().size()));
  }
  for (const Trajectory& t : all) {
    if (std::abs(t.time_step - all[0].time_step) > 1e-9) {
      throw ConfigError(fmt::format("--data: trajectories with frame steps {} s and {} s",
                                    all[0].time_step, t.time_step));
    }
  }
  return process_group().share_of(std::move(all));
}

// This process's rollouts; on process 0, every process's, in the files' trajectory order.
Row evaluate(const std::string& name, const std::string& kind, AccelerationPredictor& predictor,
             const std::vector<Trajectory>& test, const EvalArgs& args) {
  const ProcessGroup& group = process_group();
  ProgressBar progress(fmt::format("eval {}", name), static_cast<long long>(test.size()));
  EvaluationOptions options;
  options.frames = args.frames;
  options.penetration = args.penetration;
  if (group.is_root()) options.on_trajectory = [&](int done) { progress.update(done); };
  const EvaluationTotals mine = evaluate_rollout_totals(predictor, test, options);
  if (group.is_root()) progress.finish(static_cast<long long>(test.size()));
  const std::vector<double> gathered = group.collective->gather(mine.serialize());
  if (!group.is_root()) return Row{name, kind, summarize(mine, options), {}};  // not printed
  std::vector<EvaluationTotals> parts;
  for (size_t at = 0; at < gathered.size();) {
    size_t used = 0;
    parts.push_back(EvaluationTotals::deserialize(std::span(gathered).subspan(at), &used));
    at += used;
  }
  EvaluationTotals all;
  for (const EvaluationTotals& part : parts) all += part;  // process order
  // Process r holds trajectories r, r + N, …: put them back in the files' order.
  std::vector<RolloutErrors> in_file_order(all.per_trajectory.size());
  size_t next = 0;
  for (size_t r = 0; r < parts.size(); ++r) {
    for (size_t k = 0; k < parts[r].per_trajectory.size(); ++k) {
      in_file_order[r + k * parts.size()] = std::move(all.per_trajectory[next++]);
    }
  }
  all.per_trajectory = std::move(in_file_order);
  return Row{name, kind, summarize(all, options), {}};
}

void print_regimes(const std::vector<Row>& rows) {
  fmt::print(
      "\none-step error by regime, from every ground-truth frame (free flight: no collision edge "
      "in the input; rest: in contact and, in the truth, slower than 0.05 m/s and 0.25 rad/s; "
      "σ: the model's target standard deviation; ahead: the signed error along the body's motion "
      "into the step, > 0 when it keeps more speed than the truth; up: against gravity; impacts: "
      "|a - g| > 2 g in the truth, whatever the regime)\n");
  fmt::print("{:<34} {:<15} {:>7} {:>16} {:>11} {:>9} {:>14} {:>9}\n", "run", "regime", "share",
             "translation (mm)", "ahead (mm)", "up (mm)", "rotation (deg)", "RMS (σ)");
  for (const Row& row : rows) {
    if (!row.one_step) continue;
    const OneStepTotals& t = *row.one_step;
    double samples = 0;
    for (const RegimeTotals& r : t.regimes) samples += r.samples;
    const auto print_row = [&](const std::string& run, std::string_view group,
                               const RegimeTotals& r) {
      fmt::print("{:<34} {:<15} {:>6.1f}% {:>16.2f} {:>11.2f} {:>9.2f} {:>14.3f} {:>9.3f}\n", run,
                 group, 100.0 * r.samples / std::max(samples, 1.0), 1e3 * mean_translation(r),
                 1e3 * mean_ahead(r), 1e3 * mean_up(r), r.rotation / std::max(r.samples, 1.0),
                 rms_sigmas(r));
    };
    for (int k = 0; k < kRegimes; ++k) {
      print_row(k == 0 ? fmt::format("{} ({})", row.name, row.kind) : "",
                regime_name(static_cast<Regime>(k)), t.regimes[k]);
    }
    print_row("", "impacts", t.impact_errors);
    fmt::print(
        "{:<34} impacts: {:.0f} object-steps, {:.0f} ({:.1f}%) with no collision edge in "
        "their input\n",
        "", t.impact_errors.samples, t.unseen_impacts,
        100.0 * t.unseen_impacts / std::max(t.impact_errors.samples, 1.0));
  }
}

void print_table(const std::vector<Row>& rows) {
  // The run column fits the longest name ("M.h5, free flight, bf16 products (FIGNet)").
  std::vector<std::string> names;
  size_t width = 34;
  for (const Row& row : rows) {
    names.push_back(fmt::format("{} ({})", row.name, row.kind));
    width = std::max(width, names.back().size());
  }
  fmt::print("\n{:<{}} {:>21} {:>21} {:>7} {:>15} {:>10} {:>8}\n", "", width, "translation (m)",
             "rotation (deg)", "", "penetration", "face-face", "");
  fmt::print("{:<{}} {:>10} {:>10} {:>10} {:>10} {:>7} {:>7} {:>7} {:>10} {:>8}\n", "run", width,
             "mean", "last", "mean", "last", "travel", "depth", "count", "edges", "ms/step");
  for (size_t r = 0; r < rows.size(); ++r) {
    const Evaluation& e = rows[r].result;
    fmt::print(
        "{:<{}} {:>10.4f} {:>10.4f} {:>10.2f} {:>10.2f} {:>7.3f} {:>7.2f} {:>7.2f} {:>10.1f} "
        "{:>8.3f}\n",
        names[r], width, e.mean_translation, e.final_translation, e.mean_rotation, e.final_rotation,
        e.travel_ratio, e.penetration_depth_ratio, e.penetration_count_ratio, e.face_edges_per_step,
        e.milliseconds_per_step);
  }
  fmt::print(
      "\nmean: over each rollout's predicted frames, then over trajectories; last: the final "
      "frame. Travel: the distance the bodies' centres cover in the rollouts over what they cover "
      "in the ground truth (< 1: the model slows them too much). Penetration: ratio to the ground "
      "truth's (1 = as much as Bullet; nan: not measured or none in the ground truth).\n");
}

// Each row's rollout errors against the first row's, scene by scene (the rows' per-trajectory
// errors are of the same trajectories, in the same order).
SceneBySceneRow paired_against(const Row& reference, const Row& row) {
  return compare_scene_by_scene(reference.result.per_trajectory, row.result.per_trajectory,
                                reference.name, row.name);
}

// paired[k] is rows[k + 1] against rows[0].
void print_paired(const std::vector<Row>& rows, const std::vector<SceneBySceneRow>& paired) {
  std::vector<std::string> labels;
  std::vector<const SceneBySceneRow*> lines;
  for (size_t k = 0; k < paired.size(); ++k) {
    labels.push_back(fmt::format("{} ({})", rows[k + 1].name, rows[k + 1].kind));
    lines.push_back(&paired[k]);
  }
  print_scene_by_scene(fmt::format("{} ({})", rows.front().name, rows.front().kind), labels, lines,
                       34);
}

nlohmann::json to_json(const Row& row) {
  const Evaluation& e = row.result;
  const auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nullptr; };
  nlohmann::json regimes = nullptr;
  if (row.one_step) {
    regimes = nlohmann::json::object();
    const auto group = [](const RegimeTotals& r) {
      return nlohmann::json{{"object_steps", r.samples},
                            {"mean_translation_m", mean_translation(r)},
                            {"mean_ahead_m", mean_ahead(r)},
                            {"mean_up_m", mean_up(r)},
                            {"mean_rotation_deg", r.rotation / std::max(r.samples, 1.0)},
                            {"rms_sigmas", rms_sigmas(r)}};
    };
    for (int k = 0; k < kRegimes; ++k) {
      regimes[std::string(regime_name(static_cast<Regime>(k)))] = group(row.one_step->regimes[k]);
    }
    regimes["impact steps"] = group(row.one_step->impact_errors);
    regimes["impacts"] = row.one_step->impact_errors.samples;
    regimes["unseen_impacts"] = row.one_step->unseen_impacts;
  }
  return {{"name", row.name},
          {"kind", row.kind},
          {"one_step_by_regime", regimes},
          {"trajectories", e.trajectories},
          {"mean_translation_m", e.mean_translation},
          {"final_translation_m", e.final_translation},
          {"mean_rotation_deg", e.mean_rotation},
          {"final_rotation_deg", e.final_rotation},
          {"travel_ratio", number(e.travel_ratio)},
          {"penetration_depth_ratio", number(e.penetration_depth_ratio)},
          {"penetration_count_ratio", number(e.penetration_count_ratio)},
          {"face_edges_per_step", e.face_edges_per_step},
          {"milliseconds_per_step", e.milliseconds_per_step},
          {"translation_per_frame_m", e.translation},
          {"rotation_per_frame_deg", e.rotation},
          {"per_trajectory", per_trajectory_json(e.per_trajectory)}};
}

void run_eval(const EvalArgs& args) {
  use_bf16_products(args.bf16);
  const std::vector<Trajectory> test = read_test_split(args);
  const bool root = process_group().is_root();
  std::vector<Row> rows;
  int history = 2;
  std::optional<RegimeSetting> regimes;
  for (const fs::path& file : args.models) {
    auto model = std::make_shared<const Model>(load_model(file));
    const ModelConfig& config = model->config();
    if (std::abs(config.time_step - test[0].time_step) > 1e-9) {
      throw ConfigError(fmt::format("--model '{}': trained with steps of {} s, the data has {} s",
                                    file.string(), config.time_step, test[0].time_step));
    }
    history = config.graph.history;
    ModelPredictor predictor(model, {.threads = args.threads,
                                     .turns = args.turns,
                                     .mirror = args.mirror,
                                     .free_flight = args.free_flight});
    const std::string name = file.filename().string() + (args.free_flight ? ", free flight" : "") +
                             (args.bf16 ? ", bf16 products" : "");
    rows.push_back(evaluate(name, kind_of(config), predictor, test, args));
    if (args.regimes) {
      // Every row is split by the first model's graph, in its units.
      if (!regimes) {
        const Eigen::RowVectorXf& std = model->normalizers().target.std();
        regimes = RegimeSetting{config.graph, Vec3(std(0), std(1), std(2))};
      }
      rows.back().one_step = one_step_by_regime(name, predictor, test, *regimes);
    }
  }
  if (args.baseline) {
    // Constant velocity under gravity from the same given frames: what no contact model gives.
    GravityPredictor ballistic(test[0].gravity, test[0].time_step, history);
    rows.push_back(evaluate("ballistic", "constant velocity + gravity", ballistic, test, args));
    if (regimes && regimes->graph.history == history) {
      rows.back().one_step = one_step_by_regime("ballistic", ballistic, test, *regimes);
    }
  }
  if (!root) return;
  const int trajectories = rows.front().result.trajectories;
  std::vector<std::string> files;
  for (const fs::path& file : args.data) files.push_back(file.string());
  fmt::print("{} trajectories, {} frames each ({} given), from {}\n", trajectories,
             args.frames > 0 ? args.frames : test[0].num_frames(), history + 1,
             fmt::join(files, ", "));
  // Every run after the first against the first, once for the table and the JSON.
  std::vector<SceneBySceneRow> paired;
  for (size_t k = 1; k < rows.size(); ++k) paired.push_back(paired_against(rows.front(), rows[k]));
  print_table(rows);
  if (!paired.empty()) print_paired(rows, paired);
  if (regimes) print_regimes(rows);
  if (!args.json.empty()) {
    nlohmann::json out = {{"data", nlohmann::json::array()},
                          {"trajectories", trajectories},
                          {"given_frames", history + 1},
                          {"frame_step_s", test[0].time_step},
                          {"runs", nlohmann::json::array()}};
    out["data"] = files;
    for (size_t k = 0; k < rows.size(); ++k) {
      out["runs"].push_back(to_json(rows[k]));
      // Against the first run, scene by scene (absent from the first run itself).
      if (k > 0) {
        out["runs"].back()["paired_against_first"] = scene_by_scene_json(paired[k - 1]);
      }
    }
    write_text_atomically(args.json, out.dump(2) + "\n");
    fmt::print("results: {}\n", args.json.string());
  }
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand(
      "eval",
      "Roll models out over a test split: translation and rotation errors, penetration, "
      "face-face edges and time per step, next to the ballistic baseline");
  cmd->add_option("--model", args->models,
                  "Model file (repeat to compare several, e.g. FIGNet and its NoFaceCollision "
                  "ablation)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--data", args->data, "Trajectory file(s) of the test split")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--json", args->json, "Also write every figure, per frame and per trajectory");
  cmd->add_option("--frames", args->frames, "Rollout length in frames (default: all)")
      ->check(CLI::Range(4, 100000));
  cmd->add_option("--max-trajectories", args->max_trajectories,
                  "Use only the first N trajectories (default: all)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("!--no-baseline", args->baseline, "Leave out the ballistic baseline");
  cmd->add_flag("!--no-penetration", args->penetration,
                "Skip the penetration ratios (the costliest metric)");
  cmd->add_flag("!--no-regimes", args->regimes,
                "Skip the one-step errors by regime (free flight, moving contact, rest) and the "
                "count of impacts without a collision edge");
  cmd->add_option("--threads", args->threads,
                  "Threads for the network's matrix products, or with --turns for the turned "
                  "copies, one per thread (0: every core; more than one helps large scenes and "
                  "--turns on an otherwise idle machine)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--turns", args->turns,
                  "Average each prediction over the scene turned by k/turns of a turn about the "
                  "vertical (PredictionOptions::turns; turns times the cost)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  add_bf16_option(*cmd, args->bf16);
  cmd->add_flag("--mirror", args->mirror,
                "Average with the scene seen in a mirror too, at each turn (PredictionOptions::"
                "mirror; twice --turns' cost)");
  cmd->add_flag("--free-flight", args->free_flight,
                "Move bodies without a collision edge in free flight, outside the network, as "
                "FIGNetDynamicsWorld does (PredictionOptions::free_flight; always so for a model "
                "trained with omit_free_flight)");
  cmd->callback([args] { run_eval(*args); });
}

}  // namespace fignet::cli
