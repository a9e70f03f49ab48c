// `fignet stress`: the stress suite (bullet_plugin/include/fignet/bullet/stress.h) run by native
// Bullet and by FIGNet worlds, as a table on the terminal and, with --markdown, a document that
// names the command that made it.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <filesystem>

#include "commands.h"
#include "fignet/bullet/stress.h"
#include "fignet/io/model_file.h"
#include "fignet/rollout/metrics.h"
#include "fignet/rollout/predictor.h"
#include "progress.h"
#include "text_file.h"

namespace fignet::cli {

namespace {

namespace fs = std::filesystem;

struct StressArgs {
  std::vector<fs::path> models;
  fs::path markdown;
  std::vector<std::string> only;
  double length = 1.0;
  int turns = 1;
  bool mirror = false;
  std::string command_line;
};

std::string yes_no(bool v) {
  return v ? "yes" : "**NO**";
}

// How far the run 1 km away strayed from the same run at the origin, moved back.
double shift_difference(const Trajectory& far, const Trajectory& near, const Vec3& shift) {
  double largest = 0.0;
  for (size_t o = 0; o < far.objects.size(); ++o) {
    for (size_t f = 0; f < far.objects[o].poses.size(); ++f) {
      largest = std::max(
          largest,
          (far.objects[o].poses[f].position - shift - near.objects[o].poses[f].position).norm());
    }
  }
  return largest;
}

using NamedModels = std::vector<std::pair<std::string, std::shared_ptr<const Model>>>;

// Per model that records its data's materials, the cases whose dynamic bodies or floor lie
// outside them: there the model guesses. Empty when every case is within.
std::string unfamiliar_materials(const std::vector<bullet::StressCase>& cases,
                                 const NamedModels& models) {
  std::string text;
  for (const auto& [name, model] : models) {
    const ModelConfig& c = model->config();
    if (!c.friction.known() || !c.floor_friction.known()) continue;
    std::vector<std::string> listed;
    for (const bullet::StressCase& stress_case : cases) {
      int bodies = 0, outside = 0;
      for (const bullet::BodySpec& body : stress_case.scene.bodies) {
        if (body.kinematic) continue;
        ++bodies;
        outside += !familiar_material(body.properties, c);
      }
      const bool floor = stress_case.scene.floor && !familiar_floor(*stress_case.scene.floor, c);
      if (outside == 0 && !floor) continue;
      std::vector<std::string> what;
      if (floor) what.push_back("floor");
      if (outside > 0) what.push_back(fmt::format("{} of {} bodies", outside, bodies));
      listed.push_back(fmt::format("{} ({})", stress_case.name, fmt::join(what, ", ")));
    }
    if (listed.empty()) continue;
    text += fmt::format(
        "\nMaterials outside {}'s training data (bodies: friction {}, restitution {}; floor: "
        "friction {}, restitution {}), where it guesses: {}.\n",
        name, c.friction.text(), c.restitution.text(), c.floor_friction.text(),
        c.floor_restitution.text(), fmt::join(listed, "; "));
  }
  return text;
}

void run_stress(const StressArgs& args) {
  NamedModels models;
  for (const fs::path& file : args.models) {
    models.emplace_back(file.filename().string(), std::make_shared<const Model>(load_model(file)));
  }
  const std::vector<bullet::Simulator> sims =
      bullet::stress_simulators(models, args.turns, 1, args.mirror);
  const std::vector<bullet::StressCase> cases = bullet::select_stress_cases(args.only, args.length);

  std::string table =
      "| case | simulator | finite | lowest point (m) | drift (m / deg) | first-step fall | "
      "late speed (m/s) | error vs Bullet 240 Hz (m) | ms per frame |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  ProgressBar progress("stress", static_cast<long long>(cases.size()));
  std::vector<std::vector<bullet::StressRun>> results;
  for (size_t i = 0; i < cases.size(); ++i) {
    const bullet::StressCase& c = cases[i];
    results.push_back(bullet::run_stress_case(c, sims));
    progress.update(static_cast<long long>(i + 1), c.name);
    for (size_t s = 0; s < results.back().size(); ++s) {
      const bullet::StressRun& r = results.back()[s];
      std::string error = s == 0      ? "reference"
                          : c.compare ? fmt::format("{:.3f}", r.error)
                                      : fmt::format("({:.3f}, chaotic)", r.error);
      if (!c.shift.isZero() && i > 0 && cases[i - 1].group == c.group) {
        const double moved = shift_difference(r.trajectory, results[i - 1][s].trajectory, c.shift);
        error += fmt::format("; {:.2g} m from the run at the origin", moved);
      }
      table +=
          fmt::format("| {} | {} | {} | {:.3f} | {} | {} | {:.3f} | {} | {:.2f} |\n", c.name,
                      r.simulator, yes_no(r.finite), r.lowest,
                      c.at_rest ? fmt::format("{:.4f} / {:.2f}", r.drift, r.drift_degrees) : "-",
                      c.at_rest && r.finite ? fmt::format("{:.3f}", r.first_step_fall) : "-",
                      r.late_speed, error, r.milliseconds_per_frame);
    }
  }
  progress.finish(static_cast<long long>(cases.size()));
  fmt::print("\n{}", table);
  fmt::print(
      "\nlowest point: the lowest vertex over the run, relative to the floor (below -0.05 m is "
      "tunnelling or sinking); drift: largest displacement and rotation of a body started at "
      "rest; first-step fall: the largest drop of such a body in the first frame, as a fraction "
      "of free fall from rest (0 holds it, 1 lets it fall; one step, not chaotic); late speed: "
      "the fastest body over the run's second half (growth shows energy gained); error: mean "
      "translation error against Bullet at 240 Hz (chaotic scenes: for information only).\n");
  const std::string materials = unfamiliar_materials(cases, models);
  fmt::print("{}", materials);
  if (!args.markdown.empty()) {
    const std::string doc = fmt::format(
        "# Stress suite: FIGNet next to native Bullet at the extremes\n\n"
        "Generated by\n\n```sh\n{}\n```\n\n"
        "Each case is one scene run by native Bullet at 240 Hz (5 steps per 48 Hz frame) and by "
        "`FIGNetDynamicsWorld` with each model (one step per frame), twice: the network alone "
        "(`FIGNetWorldOptions::network_alone()`, what `fignet eval` measures) and the world as "
        "users get it (free flight, sleeping, the penetration, rest and energy guards: "
        "docs/bullet-world.md; the bodies of these scenes never sleep, since the harness "
        "records every body at every frame). "
        "Cases and metrics: "
        "`bullet_plugin/include/fignet/bullet/stress.h`. The lowest point is that of any vertex "
        "relative to the floor over the whole run: tunnelling or sinking shows as a large "
        "negative value. Drift and the first-step fall are measured for scenes started at rest; "
        "the late speed is the fastest body over the second half of the run.\n\n{}{}",
        args.command_line, table, materials);
    write_text_atomically(args.markdown, doc);
    fmt::print("wrote {}\n", args.markdown.string());
  }
}

}  // namespace

void add_stress_command(CLI::App& app) {
  auto args = std::make_shared<StressArgs>();
  auto* cmd = app.add_subcommand(
      "stress",
      "Run scenes at the extremes (rest, piles, stacks, sizes, densities, fast impacts, 1 km away, "
      "long rollouts, odd meshes) in native Bullet and FIGNet, and report what goes wrong");
  cmd->add_option("--model", args->models, "Model file (repeatable; none: native Bullet only)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--markdown", args->markdown, "Also write the table as a Markdown document");
  cmd->add_option("--case", args->only,
                  "Only the cases whose name contains this, or a group (repeatable: any of them)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--length", args->length,
                  "Scale every case's length (1: as specified, e.g. 2000 steps at rest)")
      ->check(CLI::Range(0.001, 10.0))
      ->capture_default_str();
  cmd->add_option("--turns", args->turns,
                  "Average each prediction over the scene turned by k/turns of a turn about the "
                  "vertical: cancels the model's sideways push at rest, at turns times the cost")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_flag("--mirror", args->mirror,
                "Average with the scene seen in a mirror too, at each turn: cancels errors with a "
                "handedness, at twice --turns' cost");
  cmd->callback([args] {
    std::string line = "build/release/tools/fignet stress";
    for (const fs::path& m : args->models) line += " --model " + m.string();
    for (const std::string& only : args->only) line += " --case '" + only + "'";
    if (args->length != 1.0) line += fmt::format(" --length {}", args->length);
    if (args->turns != 1) line += fmt::format(" --turns {}", args->turns);
    if (args->mirror) line += " --mirror";
    if (!args->markdown.empty()) line += " --markdown " + args->markdown.string();
    args->command_line = line;
    run_stress(*args);
  });
}

}  // namespace fignet::cli
