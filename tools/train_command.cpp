// `fignet train`: trains a model on trajectory files with periodic validation rollouts, atomic
// checkpoints, exact resume, and a clean stop on Ctrl-C / SIGTERM.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>

#include "commands.h"
#include "device_option.h"
#include "fignet/bullet/stress.h"
#include "fignet/error.h"
#include "fignet/io/checkpoint.h"
#include "fignet/io/model_file.h"
#include "fignet/io/trajectory_file.h"
#include "fignet/nn/gemm.h"
#include "fignet/rollout/evaluation.h"
#include "fignet/train/grow.h"
#include "fignet/train/training_config.h"
#include "process_group.h"
#include "progress.h"
#include "stop_signals.h"
#include "training_log.h"

namespace fignet::cli {

namespace {

namespace fs = std::filesystem;

struct TrainArgs {
  std::vector<fs::path> data;
  fs::path valid, config_file, out, checkpoint, log;
  std::string preset = "paper";
  std::vector<std::string> settings;
  std::int64_t steps = -1;
  bool resume = false;
  int deepen = 0;               // message-passing steps added to the resumed run's model
  float deepen_scale = 0.0f;    // their LayerNorm scales at the start (0: the identity)
  int widen_hidden = 0;         // the resumed run's MLPs' hidden width grown to this (0: kept)
  int widen_object_hidden = 0;  // ... and its object-node MLPs'
  double checkpoint_minutes = 10.0;
  std::int64_t log_every = 100, valid_every = 2000;
  int valid_trajectories = 10, threads = 0;
  std::vector<std::string> valid_stress;  // stress cases run at each validation
  double valid_stress_length = 1.0;
  DeviceArgs device;
};

// The run's config: preset, then the JSON file, then --set overrides, then --steps.
// decay_steps follows the run's length unless set.
TrainingConfig resolve_config(const TrainArgs& args) {
  TrainingConfig config = TrainingConfig::preset_named(args.preset);
  if (!args.config_file.empty()) {
    std::ifstream in(args.config_file);
    if (!in) throw FileError(fmt::format("--config '{}': cannot open", args.config_file.string()));
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    config.apply_json(text, fmt::format("--config '{}'", args.config_file.string()));
  }
  for (const std::string& setting : args.settings) config.apply_setting(setting);
  if (args.steps >= 0) config.steps = args.steps;
  // The learning rate decays over the run's length (from decay_start_step) unless decay_steps
  // was given.
  if (!config.decay_steps_given) {
    config.trainer.adam.decay_steps =
        std::max<std::int64_t>(1, config.steps - config.trainer.adam.decay_start_step);
  }
  return config;
}

// The finest mesh of the data: the resolution the model will know (metadata, no parameter
// depends on it, so a resumed run may record it too).
int most_mesh_vertices(const std::vector<Trajectory>& data) {
  int most = 0;
  for (const Trajectory& t : data)
    for (const TrajectoryObject& object : t.objects)
      most = std::max(most, object.mesh->num_vertices());
  return most;
}

// The lightest and heaviest dynamic body of the data (metadata like the above; under mpirun the
// share process 0 read, whose 700+ trajectories hold MOVi's whole range).
void record_masses(const std::vector<Trajectory>& data, ModelConfig& model) {
  MassRange masses;
  for (const Trajectory& t : data) masses.add(t.objects);
  if (masses.empty()) return;
  model.min_mass = masses.lightest;
  model.max_mass = masses.heaviest;
}

// The friction and restitution of the data's bodies and floors (metadata like the above).
void record_materials(const std::vector<Trajectory>& data, ModelConfig& model) {
  model.friction = model.restitution = model.floor_friction = model.floor_restitution = {};
  for (const Trajectory& t : data) {
    for (const TrajectoryObject& object : t.objects) {
      model.friction.add(object.properties.friction);
      model.restitution.add(object.properties.restitution);
    }
    if (t.floor) {
      model.floor_friction.add(t.floor->properties.friction);
      model.floor_restitution.add(t.floor->properties.restitution);
    }
  }
}

// Time step and gravity come from the data, which must agree on them.
void adopt_physics(const std::vector<Trajectory>& data, ModelConfig& model) {
  model.time_step = data.front().time_step;
  model.gravity = data.front().gravity;
  model.mesh_vertices = most_mesh_vertices(data);
  record_masses(data, model);
  record_materials(data, model);
  for (size_t i = 0; i < data.size(); ++i) {
    if (data[i].time_step != model.time_step || data[i].gravity != model.gravity) {
      throw ConfigError(fmt::format(
          "trajectory {} has time step {} s and gravity ({}, {}, {}), trajectory 0 {} s and "
          "({}, {}, {}): train on one physical setting",
          i, data[i].time_step, data[i].gravity.x(), data[i].gravity.y(), data[i].gravity.z(),
          model.time_step, model.gravity.x(), model.gravity.y(), model.gravity.z()));
    }
  }
}

// --set on a resumed run: the trainer's fields (loss, optimizer, sampling) and the training noise
// may change, which makes the continuation a new run from the checkpoint's weights and optimizer
// state; the model's other fields may not, since the parameters and normalisers were made for
// them.
void apply_resume_settings(const std::vector<std::string>& settings, TrainingConfig& config,
                           bool root) {
  if (settings.empty()) return;
  TrainingConfig changed = config;
  for (const std::string& setting : settings) changed.apply_setting(setting);
  for (const std::string& name : config.differing_fields(changed)) {
    if (!TrainingConfig::changes_on_resume(name)) {
      throw ConfigError(fmt::format(
          "--set {}: a resumed run keeps its model's fields (the checkpoint has {} = {}); only "
          "the training noise, random_yaw and the trainer's fields (batch_size and after in "
          "--help's list) may change",
          name, name, config.field_text(name)));
    }
    if (name == "steps") continue;  // --steps has the last word on the run's length
    if (root) {
      fmt::print("changed on resume: {} {} -> {}\n", name, config.field_text(name),
                 changed.field_text(name));
    }
  }
  // Every model field that differs passed changes_on_resume above: the model may be taken whole.
  config.trainer = changed.trainer;
  config.model = changed.model;
}

// One validation's stress cases in a line: each case's drift (started at rest) or error against
// Bullet, the network alone / the world (runs 1 and 2 of stress_simulators with one model).
std::string stress_summary(const std::vector<bullet::StressCase>& cases,
                           const std::vector<std::vector<bullet::StressRun>>& runs) {
  std::vector<std::string> parts;
  for (size_t i = 0; i < cases.size(); ++i) {
    const auto value = [&](const bullet::StressRun& run) {
      if (!run.finite) return std::string("not finite");
      return fmt::format("{:.3f}", cases[i].at_rest ? run.drift : run.error);
    };
    parts.push_back(fmt::format("{} {} {} / {} m", cases[i].name,
                                cases[i].at_rest ? "drift" : "error", value(runs[i][1]),
                                value(runs[i][2])));
  }
  return fmt::format("{}", fmt::join(parts, "; "));
}

void run_train(const TrainArgs& args) {
  // Before any thread of OpenMP starts: those threads inherit the blocked signals.
  StopSignals stop_signals;
  if (args.threads > 0) omp_set_num_threads(args.threads);
  const fs::path checkpoint_path =
      args.checkpoint.empty() ? fs::path(args.out.string() + ".ckpt.h5") : args.checkpoint;
  const fs::path log_path =
      args.log.empty() ? fs::path(args.out.string() + ".log.jsonl") : args.log;
  for (const fs::path& file : {args.out, checkpoint_path, log_path}) {
    const fs::path parent = file.parent_path();
    if (!parent.empty() && !fs::is_directory(parent)) {
      throw FileError(
          fmt::format("'{}': folder '{}' does not exist", file.string(), parent.string()));
    }
  }
  // Under mpirun each process reads its share of the trajectories; process 0 alone validates,
  // prints, logs and writes checkpoints.
  const ProcessGroup& group = process_group();
  const bool root = group.is_root();
  // A misspelt stress case fails here, not at the first validation.
  std::vector<bullet::StressCase> stress_cases;
  if (root && !args.valid_stress.empty()) {
    stress_cases =
        bullet::select_stress_cases(args.valid_stress, args.valid_stress_length, "--valid-stress");
  }
  const std::vector<Trajectory> data =
      read_trajectories(args.data, TrajectoryShare{group.rank(), group.size()});
  std::vector<Trajectory> valid;
  if (root && !args.valid.empty()) {
    valid = read_trajectories(args.valid);
    valid.resize(std::min<size_t>(valid.size(), args.valid_trajectories));
  }

  // A new run, or the checkpoint's run continued with its own config.
  TrainingConfig config = resolve_config(args);
  std::shared_ptr<const Model> initial;
  TrainerState state;
  int resumed_batch_size = 0;  // the checkpoint's, before any --set
  if (args.resume) {
    Checkpoint checkpoint = load_checkpoint(checkpoint_path);
    if (args.deepen > 0) {
      const int trained = checkpoint.model->config().message_passing_steps;
      GrownRun deeper = deepen(*checkpoint.model, checkpoint.state, args.deepen, args.deepen_scale);
      checkpoint.model = std::move(deeper.model);
      checkpoint.state = std::move(deeper.state);
      if (root) {
        fmt::print(
            "deepened: message_passing_steps {} -> {} ({})\n", trained,
            checkpoint.model->config().message_passing_steps,
            args.deepen_scale == 0.0f
                ? "the new steps start as the identity: the same predictions"
                : fmt::format("the new steps' LayerNorm scales start at {}", args.deepen_scale));
      }
    }
    if (args.widen_hidden > 0 || args.widen_object_hidden > 0) {
      const ModelConfig& trained = checkpoint.model->config();
      const int hidden = trained.mlp_hidden(), object_hidden = trained.object_mlp_hidden();
      GrownRun wider =
          widen(*checkpoint.model, checkpoint.state, args.widen_hidden, args.widen_object_hidden);
      checkpoint.model = std::move(wider.model);
      checkpoint.state = std::move(wider.state);
      if (root) {
        fmt::print(
            "widened: MLPs' hidden width {} -> {}, object-node MLPs' {} -> {} (new units' "
            "outgoing weights start at zero: the same predictions)\n",
            hidden, checkpoint.model->config().mlp_hidden(), object_hidden,
            checkpoint.model->config().object_mlp_hidden());
      }
    }
    const std::int64_t steps = config.steps;
    config.model = checkpoint.model->config();
    if (config.model.mesh_vertices == 0) config.model.mesh_vertices = most_mesh_vertices(data);
    if (config.model.max_mass == 0.0) record_masses(data, config.model);
    if (!config.model.friction.known()) record_materials(data, config.model);
    config.trainer = checkpoint.trainer_config;
    resumed_batch_size = config.trainer.batch_size;
    // The run's own length unless --steps says otherwise.
    config.steps = args.steps >= 0                ? steps
                   : checkpoint.planned_steps > 0 ? checkpoint.planned_steps
                                                  : std::max(steps, checkpoint.state.step);
    initial = checkpoint.model;
    state = std::move(checkpoint.state);
    if (root) fmt::print("resuming {} at step {}\n", checkpoint_path.string(), state.step);
    if (config.steps < state.step) {
      throw ConfigError(fmt::format("--steps {}: the checkpoint is already at step {}",
                                    config.steps, state.step));
    }
    apply_resume_settings(args.settings, config, root);
  } else {
    adopt_physics(data, config.model);
  }
  config.validate();
  if (config.trainer.batch_size < group.size()) {
    throw ConfigError(
        fmt::format("batch_size = {} is smaller than the {} processes: each needs "
                    "at least one sample per step",
                    config.trainer.batch_size, group.size()));
  }
  if (root) {
    fmt::print("config:\n{}\n", config.to_json());
    fmt::print("data: {} trajectories{}; validation: {} trajectories{}\n", data.size(),
               group.size() > 1 ? fmt::format(" on process 0 of {}", group.size()) : "",
               valid.size(),
               stress_cases.empty() ? ""
                                    : fmt::format(" and {} stress case{}", stress_cases.size(),
                                                  stress_cases.size() == 1 ? "" : "s"));
  }

  Trainer trainer(config.model, config.trainer, data, initial.get(), group.collective);
  if (args.resume) trainer.restore(state);
  if (auto backend = make_backend(args.device, trainer.network())) {
    trainer.set_backend(std::move(backend));
    // A GPU leaves the cores free while it runs the passes: the next batch is built meanwhile.
    trainer.set_build_ahead(true);
  }
  if (root) {
    fmt::print("network passes on: {}{}\n", trainer.backend().name(),
               gemm_precision() == GemmPrecision::kBf16 ? " (bf16 products)" : "");
  }
  if (!args.resume && config.trainer.statistics_warmup > 0) {
    if (root) fmt::print("statistics warm-up: {} batches", config.trainer.statistics_warmup);
    std::fflush(stdout);
    trainer.warm_up_statistics(config.trainer.statistics_warmup);
    if (root) fmt::print(" ({:.1f} s)\n", trainer.times().warmup);
    std::fflush(stdout);
  }
  std::optional<TrainingLog> log;
  if (root)
    log.emplace(log_path, trainer.steps_done(), resumed_batch_size, config.trainer.batch_size);

  auto save = [&] {
    if (!root) return;  // every process holds the same model and optimizer state
    save_checkpoint(trainer, checkpoint_path, config.steps);
    save_model(*trainer.model(), args.out);
  };
  // Processes stop together, at the same step, or the others would wait in a sum forever.
  auto stop_agreed = [&] {
    double stop = stop_signals.requested() ? 1.0 : 0.0;
    if (group.size() > 1) group.collective->sum(std::span<double>(&stop, 1));
    return stop > 0.0;
  };
  // Validation (process 0): rollouts of the held-out trajectories with the one-step errors by
  // regime, and the stress cases asked for, the network alone and the world as users get it.
  auto validate = [&](std::int64_t step) {
    if (!root || (valid.empty() && stress_cases.empty())) return;
    // One thread per trajectory or case (Eigen runs each predictor's products on its own thread
    // inside a parallel region; 0 leaves its process-wide setting alone).
    const std::shared_ptr<const Model> model = trainer.model();
    const int threads = std::max(1, omp_get_max_threads());
    if (!valid.empty()) {
      const auto make_predictor = [&] { return std::make_unique<ModelPredictor>(model, 0); };
      const Evaluation e = evaluate_rollouts_parallel(make_predictor, valid, threads);
      // Where the error is: free flight, moving contact, rest (in the model's units too).
      const Eigen::RowVectorXf& target_std = model->normalizers().target.std();
      const OneStepTotals one_step = one_step_totals_parallel(
          make_predictor, model->config().graph, Vec3(target_std(0), target_std(1), target_std(2)),
          valid, threads);
      log->write_validation(step, e, one_step);
      fmt::print(
          stderr,
          "\nstep {}: validation translation {:.4f} m, rotation {:.2f} deg; one step: free "
          "flight {:.2f} mm, moving contact {:.2f} mm, rest {:.2f} mm\n",
          step, e.mean_translation, e.mean_rotation, 1e3 * mean_translation(one_step.regimes[0]),
          1e3 * mean_translation(one_step.regimes[1]), 1e3 * mean_translation(one_step.regimes[2]));
    }
    if (!stress_cases.empty()) {
      const std::vector<bullet::Simulator> sims =
          bullet::stress_simulators({{args.out.filename().string(), model}}, 1, 0);
      const auto runs = bullet::run_stress_cases(stress_cases, sims, threads);
      log->write_stress(step, stress_cases, runs);
      fmt::print(stderr, "step {}: stress (network alone / world): {}\n", step,
                 stress_summary(stress_cases, runs));
    }
  };
  ProgressBar bar(root ? "train" : "", config.steps, trainer.steps_done());
  const std::int64_t first_step = trainer.steps_done();
  auto last_checkpoint = std::chrono::steady_clock::now();
  double loss_sum = 0.0, norm_sum = 0.0, gap_sum = 0.0;
  int loss_count = 0;
  std::int64_t window_start_step = trainer.steps_done();
  double window_start_time = bar.seconds();
  bool stopped = false;
  while (trainer.steps_done() < config.steps && !(stopped = stop_agreed())) {
    const TrainStep step = trainer.step();
    loss_sum += step.loss, norm_sum += step.gradient_norm, gap_sum += step.heading_gap;
    ++loss_count;
    if (!root) continue;
    if (step.step % args.log_every == 0 || step.step == config.steps) {
      const double now = bar.seconds();
      const double rate = (step.step - window_start_step) / std::max(1e-9, now - window_start_time);
      const bool consistent = config.trainer.heading_consistency > 0.0f;
      log->write_step(step.step, loss_sum / loss_count, step.learning_rate, rate,
                      norm_sum / loss_count, consistent ? gap_sum / loss_count : -1.0);
      bar.update(step.step,
                 fmt::format("loss {:.4f}  {:.1f} steps/s  {:.0f} samples/s", loss_sum / loss_count,
                             rate, rate * config.trainer.batch_size));
      loss_sum = 0.0, norm_sum = 0.0, gap_sum = 0.0, loss_count = 0;
      window_start_step = step.step, window_start_time = now;
    }
    if (step.step % args.valid_every == 0 || step.step == config.steps) validate(step.step);
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_checkpoint).count() >=
        60.0 * args.checkpoint_minutes) {
      save();
      last_checkpoint = now;
    }
  }
  save();
  if (!root) return;
  bar.finish(trainer.steps_done());
  const TrainerTimes& times = trainer.times();
  const double steps_run =
      std::max<double>(1.0, static_cast<double>(trainer.steps_done() - first_step));
  fmt::print(
      "per step ({} scenes): {:.1f} ms building graphs{}, {:.1f} ms input statistics, {:.1f} ms "
      "network ({}), {:.1f} ms Adam{}{}\n",
      config.trainer.batch_size, 1e3 * times.build / steps_run,
      trainer.builds_ahead()
          ? fmt::format(" ({:.1f} ms of it waited for, the rest beside the step before)",
                        1e3 * times.build_waited / steps_run)
          : "",
      1e3 * times.statistics / steps_run, 1e3 * times.network / steps_run, trainer.backend().name(),
      1e3 * times.optimizer / steps_run,
      config.trainer.pushforward_fraction > 0.0f
          ? fmt::format(", {:.1f} ms pushing scenes forward (its forward passes and graphs)",
                        1e3 * times.pushforward / steps_run)
          : "",
      config.trainer.heading_consistency > 0.0f
          ? fmt::format(", {:.1f} ms predicting turned copies (heading_consistency)",
                        1e3 * times.heading / steps_run)
          : "");
  if (const std::string profile = trainer.backend().profile(); !profile.empty()) {
    fmt::print("{}: {}\n", trainer.backend().name(), profile);
  }
  if (group.size() > 1) {
    const double seconds = bar.seconds();
    const double talking = group.collective->seconds_communicating();
    fmt::print("{} processes: {:.1f} s in gradient and statistics sums of {:.1f} s ({:.1f} %)\n",
               group.size(), talking, seconds, 100.0 * talking / std::max(seconds, 1e-9));
  }
  if (stopped) {
    fmt::print("stopped at step {}; checkpoint {} (continue with --resume)\n", trainer.steps_done(),
               checkpoint_path.string());
  } else {
    // A resumed run says what this process added as well as where the run stands.
    const std::int64_t added = trainer.steps_done() - first_step;
    std::string steps = fmt::format("trained {} step{}", added, added == 1 ? "" : "s");
    if (first_step > 0) steps += fmt::format(" (step {} to {})", first_step, trainer.steps_done());
    fmt::print("{}; model {}, checkpoint {}, log {}\n", steps, args.out.string(),
               checkpoint_path.string(), log_path.string());
  }
}

}  // namespace

void add_train_command(CLI::App& app) {
  auto args = std::make_shared<TrainArgs>();
  auto* cmd = app.add_subcommand("train", "Train a FIGNet model on trajectory files");
  cmd->add_option("--data", args->data, "Training trajectory files (shards are concatenated)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--valid", args->valid, "Held-out trajectory file for validation rollouts")
      ->check(CLI::ExistingFile);
  auto* preset =
      cmd->add_option(
             "--preset", args->preset,
             "Model preset: paper (L=128, M=10) or small (L=64, M=5), both with the "
             "recipe of docs/training-study.md (batch 8, ...; on a GPU --set batch_size=128)")
          ->check(CLI::IsMember(ModelConfig::preset_names()))
          ->capture_default_str();
  auto* config =
      cmd->add_option("--config", args->config_file, "JSON file of config fields (see --set)")
          ->check(CLI::ExistingFile);
  cmd->add_option(
      "--set", args->settings, "Override one config field, key=value (repeatable). Fields: " + [] {
        std::string names;
        for (const auto& n : TrainingConfig::field_names())
          names += (names.empty() ? "" : ", ") + n;
        return names;
      }());
  cmd->add_option("--steps", args->steps, "Total optimisation steps (overrides the config)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1'000'000'000}));
  cmd->add_option("--out", args->out, "Model file written at every checkpoint and at the end")
      ->required();
  cmd->add_option("--checkpoint", args->checkpoint, "Checkpoint file (default: OUT.ckpt.h5)");
  // A resumed run keeps its checkpoint's config unless --set changes a trainer field or the noise.
  cmd->add_flag("--resume", args->resume,
                "Continue the run in the checkpoint file exactly where it stopped, with its "
                "config; --steps and --set of the training noise (noise_std, noise, "
                "noise_correction), random_yaw and the trainer's fields (batch_size onwards) may "
                "change it")
      ->excludes(preset)
      ->excludes(config);
  cmd->add_option("--deepen", args->deepen,
                  "With --resume: add this many message-passing steps to the run's model, spread "
                  "among its trained ones, each starting as the identity (so the deeper network "
                  "first predicts what the trained one did) unless --deepen-scale says otherwise; "
                  "the run continues deeper in the same files, so copy them first to keep the "
                  "original")
      ->check(CLI::Range(1, 64))
      ->needs("--resume");
  cmd->add_option("--deepen-scale", args->deepen_scale,
                  "With --deepen: the new steps' LayerNorm scales at the start (0: the identity; "
                  "a small positive one, e.g. 0.1, lets their weights learn from the first step)")
      ->check(CLI::Range(0.0f, 1.0f))
      ->needs("--deepen")
      ->capture_default_str();
  cmd->add_option("--widen-hidden", args->widen_hidden,
                  "With --resume: widen the hidden layers of the run's MLPs to this many units "
                  "(hidden_size; new units start with zero outgoing weights, so the wider network "
                  "first predicts what the trained one did); the run continues wider in the same "
                  "files, so copy them first to keep the original")
      ->check(CLI::Range(1, 4096))
      ->needs("--resume");
  cmd->add_option("--widen-object-hidden", args->widen_object_hidden,
                  "With --resume: the same for the object-node MLPs alone (object_hidden_size: "
                  "one row per body, so nearly free)")
      ->check(CLI::Range(1, 4096))
      ->needs("--resume");
  cmd->add_option("--checkpoint-minutes", args->checkpoint_minutes, "Minutes between checkpoints")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->add_option("--log", args->log,
                  "JSON-lines log of loss and validation (default: OUT.log.jsonl)");
  cmd->add_option("--log-every", args->log_every, "Steps between log lines")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1'000'000}))
      ->capture_default_str();
  cmd->add_option("--valid-every", args->valid_every, "Steps between validation rollouts")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1'000'000'000}))
      ->capture_default_str();
  cmd->add_option("--valid-trajectories", args->valid_trajectories,
                  "Validation trajectories rolled out each time")
      ->check(CLI::Range(1, 100'000))
      ->capture_default_str();
  cmd->add_option("--valid-stress", args->valid_stress,
                  "Also run these cases of `fignet stress` at each validation, the network alone "
                  "and the world, and log their drift and late speed (a name's part or a group, "
                  "as stress --case; repeatable), e.g. --valid-stress rest --valid-stress stacks")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option(
         "--valid-stress-length", args->valid_stress_length,
         "Scale the stress cases' lengths (as stress --length; 1: e.g. 2000 steps at rest)")
      ->check(CLI::Range(0.001, 10.0))
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: every core)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  add_device_options(*cmd, args->device);
  cmd->callback([args] { run_train(*args); });
}

}  // namespace fignet::cli
