#include "fignet/train/trainer.h"

#include <fmt/format.h>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <utility>

#include "fignet/error.h"
#include "fignet/rollout/rollout.h"
#include "parallel/background_task.h"
#include "parallel/parallel_for.h"

namespace fignet {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One process: sums are the values themselves.
Collective& single_process() {
  static Collective one;
  return one;
}

// The inputs' and targets' normalisers in one fixed order.
std::vector<Normalizer*> all_of(Normalizers& n) {
  std::vector<Normalizer*> all = {&n.mesh_node, &n.object_node, &n.face_edge, &n.target};
  for (Normalizer& edge : n.edges) all.push_back(&edge);
  return all;
}

}  // namespace

Trainer::Trainer(const ModelConfig& config, const TrainerConfig& trainer_config,
                 const std::vector<Trajectory>& data, const Model* initial, Collective* collective)
    : config_(config),
      trainer_config_(trainer_config),
      data_(data),
      network_(config),
      normalizers_(network_.make_normalizers()),
      collective_(collective ? collective : &single_process()),
      backend_(make_cpu_backend(network_)) {
  if (trainer_config.batch_size < 1) {
    throw ConfigError(
        fmt::format("trainer: batch_size = {} (must be >= 1)", trainer_config.batch_size));
  }
  for (const Trajectory& trajectory : data_) trajectory.validate();
  samples_ = enumerate_samples(data_, config.graph.history);
  if (samples_.empty()) {
    throw ConfigError(
        fmt::format("trainer: no training samples{}: every trajectory needs more than "
                    "history + 1 = {} frames",
                    collective_->size() > 1
                        ? fmt::format(" in the share of process {} of {} ({} trajectories)",
                                      collective_->rank(), collective_->size(), data_.size())
                        : "",
                    config.graph.history + 1));
  }
  if (initial) {
    params_ = initial->parameters();
    normalizers_ = initial->normalizers();
  } else {
    network_.layout().initialize(params_, config.seed);
  }
  grads_.assign(params_.size(), 0.0f);
  adam_ = Adam(params_.size(), trainer_config.adam);
  if (!(trainer_config.weight_average >= 0.0f && trainer_config.weight_average < 1.0f)) {
    throw ConfigError(fmt::format("trainer: weight_average = {} (must be in [0, 1); 0: none)",
                                  trainer_config.weight_average));
  }
  // The average starts at the starting parameters (restore() replaces it with a checkpoint's).
  if (trainer_config.weight_average > 0.0f) averaged_params_ = params_;
  if (!(trainer_config.impact_loss_weight >= 0.0f) ||
      !std::isfinite(trainer_config.impact_loss_weight)) {
    throw ConfigError(fmt::format("trainer: impact_loss_weight = {} (must be >= 0; 1: off)",
                                  trainer_config.impact_loss_weight));
  }
  if (!(trainer_config.still_air_fraction >= 0.0f && trainer_config.still_air_fraction <= 1.0f)) {
    throw ConfigError(fmt::format("trainer: still_air_fraction = {} (must be in [0, 1]; 0: none)",
                                  trainer_config.still_air_fraction));
  }
  if (!(trainer_config.pushforward_fraction >= 0.0f &&
        trainer_config.pushforward_fraction <= 1.0f)) {
    throw ConfigError(fmt::format("trainer: pushforward_fraction = {} (must be in [0, 1]; 0: none)",
                                  trainer_config.pushforward_fraction));
  }
  if (trainer_config.pushforward_steps < 1 ||
      trainer_config.pushforward_steps > kMaxPushforwardSteps) {
    throw ConfigError(fmt::format("trainer: pushforward_steps = {} (must be in 1..{})",
                                  trainer_config.pushforward_steps, kMaxPushforwardSteps));
  }
  if (!(trainer_config.heading_consistency >= 0.0f) ||
      !std::isfinite(trainer_config.heading_consistency)) {
    throw ConfigError(fmt::format("trainer: heading_consistency = {} (must be >= 0; 0: none)",
                                  trainer_config.heading_consistency));
  }
  if (trainer_config.pushforward_fraction > 0.0f && config.graph.history < 1) {
    throw ConfigError(
        "trainer: pushforward_fraction > 0 needs history >= 1 (a velocity to push forward)");
  }
}

int Trainer::local_batch_size(int batch) const {
  const int n = collective_->size(), r = collective_->rank();
  return batch / n + (r < batch % n ? 1 : 0);
}

std::mt19937_64 Trainer::step_generator(std::int64_t step) const {
  const auto seed = trainer_config_.seed;
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         static_cast<std::uint32_t>(collective_->rank()),
                         static_cast<std::uint32_t>(step),
                         static_cast<std::uint32_t>(static_cast<std::uint64_t>(step) >> 32)};
  return std::mt19937_64(sequence);
}

Trainer::~Trainer() = default;

void Trainer::build_current(const std::vector<SampleRef>& samples, std::mt19937_64 noise) {
  build_batch(samples, noise, true, omp_get_max_threads(), current());
  times_.build += current().build_seconds;
}

void Trainer::build_current(std::int64_t counter) {
  draw_and_build(counter, omp_get_max_threads(), current());
  times_.build += current().build_seconds;
}

void Trainer::draw_and_build(std::int64_t counter, int threads, PreparedBatch& batch) const {
  const std::uint64_t noise_seed = draw_batch(counter, batch.samples);
  // The statistics warm-up's batches (counters below 0) come before any prediction worth pushing.
  build_batch(batch.samples, std::mt19937_64(noise_seed), counter >= 0, threads, batch);
}

void Trainer::build_batch(const std::vector<SampleRef>& samples, std::mt19937_64 noise,
                          bool may_push, int threads, PreparedBatch& batch) const {
  const auto start = std::chrono::steady_clock::now();
  for (const SampleRef& sample : samples) {
    if (sample.trajectory < 0 || sample.trajectory >= static_cast<int>(data_.size())) {
      throw ConfigError(fmt::format("trainer: sample of trajectory {} (this process has {})",
                                    sample.trajectory, data_.size()));
    }
  }
  // The pushforward finds the samples here (draw_and_build draws them in place).
  if (&samples != &batch.samples) batch.samples = samples;
  const int h = config_.graph.history;
  const int scenes = static_cast<int>(samples.size());
  batch.scenes.resize(scenes);
  batch.scene_targets.resize(scenes);
  if (flags_motion()) batch.scene_motion.resize(scenes);
  // One noise seed per scene, drawn in scene order: the noise does not depend on the threads.
  batch.scene_seeds.resize(scenes);
  for (std::uint64_t& seed : batch.scene_seeds) seed = noise();
  // Whether this batch is pushed forward, from a generator of its own: runs without the
  // pushforward draw what they always drew.
  bool pushes = false;
  if (may_push && trainer_config_.pushforward_fraction > 0.0f && scenes > 0) {
    std::seed_seq push_seeds{static_cast<std::uint32_t>(batch.scene_seeds[0]),
                             static_cast<std::uint32_t>(batch.scene_seeds[0] >> 32),
                             std::uint32_t{0x9057}};
    std::mt19937_64 push(push_seeds);
    pushes = std::uniform_real_distribution<double>(0.0, 1.0)(push) <
             trainer_config_.pushforward_fraction;
  }
  batch.scene_pushed.assign(scenes, 0);
  batch.scene_yaw.assign(config_.random_yaw ? scenes : 0, 0.0);
  auto make_samples = [&](int begin, int end) {
    for (int b = begin; b < end; ++b) {
      const Trajectory& trajectory = data_[samples[b].trajectory];
      const std::uint64_t scene_seed = batch.scene_seeds[b];
      std::mt19937_64 rng(scene_seed);
      // Its own generator: runs without still bodies in the air draw the noise they always drew.
      double gap = 0.0;
      if (trainer_config_.still_air_fraction > 0.0f && can_hold_still_in_air(trajectory)) {
        std::seed_seq still_seeds{static_cast<std::uint32_t>(scene_seed),
                                  static_cast<std::uint32_t>(scene_seed >> 32),
                                  std::uint32_t{0x57111}};
        std::mt19937_64 still(still_seeds);
        if (std::uniform_real_distribution<double>(0.0, 1.0)(still) <
            trainer_config_.still_air_fraction) {
          gap = std::exp(std::uniform_real_distribution<double>(std::log(kStillAirGaps[0]),
                                                                std::log(kStillAirGaps[1]))(still));
        }
      }
      // A pushed scene starts up to pushforward_steps frames early, no earlier than the first
      // frame with a history; push_forward_current brings it to its own frame.
      const int push_steps = pushes && gap == 0.0 ? std::clamp(samples[b].frame - h, 0,
                                                               trainer_config_.pushforward_steps)
                                                  : 0;
      const bool pushed = push_steps > 0;
      batch.scene_pushed[b] = static_cast<std::uint8_t>(push_steps);
      if (gap > 0.0) {
        make_still_sample_in_air(trajectory, samples[b].frame, h, gap, config_.noise_std,
                                 config_.noise, config_.noise_correction, rng, batch.scenes[b],
                                 batch.scene_targets[b]);
      } else {
        make_noisy_sample(trajectory, samples[b].frame - push_steps, h, config_.noise_std,
                          config_.noise, config_.noise_correction, rng, batch.scenes[b],
                          batch.scene_targets[b]);
      }
      // Drawn after the noise: a run without the turn draws the same noise as before it existed.
      // A pushed scene is turned once it is pushed (the truth it is advanced with is unturned).
      if (config_.random_yaw) {
        std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi);
        batch.scene_yaw[b] = angle(rng);
        if (!pushed)
          turn_about_vertical(batch.scene_yaw[b], batch.scenes[b], batch.scene_targets[b]);
      }
      if (flags_motion()) {
        if (gap > 0.0) {
          // Every dynamic body is still, in the air.
          batch.scene_motion[b].assign(trajectory.objects.size(), kResting);
        } else {
          batch.scene_motion[b] =
              resting_objects(trajectory, samples[b].frame, kRestSpeed * trajectory.time_step);
          if (trainer_config_.impact_loss_weight != 1.0f) {
            mark_impacts(trajectory, samples[b].frame, kImpactG, batch.scene_motion[b]);
          }
        }
      }
    }
  };
  build_graph(threads, batch, make_samples);
  batch.build_seconds = seconds_since(start);
}

void Trainer::build_graph(int threads, PreparedBatch& batch,
                          const std::function<void(int, int)>& prepare_scenes) const {
  const int scenes = static_cast<int>(batch.scenes.size());
  // With omit_free_flight the graph holds each scene's objects with a collision edge only: the
  // others fall by gravity in every rollout of the model, so neither the network nor its loss
  // sees them.
  const bool omit = config_.graph.omit_free_flight;
  if (omit) {
    batch.free_flight.resize(scenes);
    batch.kept_scenes.resize(scenes);
    batch.kept_contacts.resize(scenes);
    batch.kept_targets.resize(scenes);
    batch.kept_motion.resize(batch.scene_motion.size());
  }
  auto prepare_and_split = [&](int begin, int end, GraphBuilder& builder) {
    prepare_scenes(begin, end);
    if (!omit) return;
    for (int b = begin; b < end; ++b) {
      FreeFlightSplit& split = batch.free_flight[b];
      split.split(builder, batch.scenes[b], nullptr, batch.kept_scenes[b], batch.kept_contacts[b]);
      split.keep_rows(batch.scenes[b], batch.scene_targets[b], batch.kept_targets[b]);
      if (batch.scene_motion.empty()) continue;
      batch.kept_motion[b].clear();
      for (const int o : split.kept_objects()) {
        batch.kept_motion[b].push_back(batch.scene_motion[b][o]);
      }
    }
  };
  const std::vector<Scene>& graph_scenes = omit ? batch.kept_scenes : batch.scenes;
  auto build_part = [&](int begin, int end, GraphBuilder& builder, Graph& graph) {
    const std::span<const Scene> part = std::span(graph_scenes).subspan(begin, end - begin);
    if (omit) {
      builder.build_with_contacts(part, std::span(batch.kept_contacts).subspan(begin, end - begin),
                                  graph);
    } else {
      builder.build(part, graph);
    }
  };
  // Contiguous runs of scenes, one run per thread (the graph is the same however they are cut:
  // each part's nodes and edges are appended in scene order).
  const int parts = std::clamp(std::min(threads, scenes), 1, 64);
  while (static_cast<int>(batch.builders.size()) < parts)
    batch.builders.emplace_back(config_.graph);
  if (parts == 1) {
    prepare_and_split(0, scenes, batch.builders[0]);
    build_part(0, scenes, batch.builders[0], batch.graph);
  } else {
    if (static_cast<int>(batch.part_graphs.size()) < parts) batch.part_graphs.resize(parts);
    // The first part is built straight into the batch graph, the others beside it.
    detail::parallel_for(parts, parts, detail::Schedule::kContiguous, [&](int i) {
      const int begin = scenes * i / parts, end = scenes * (i + 1) / parts;
      prepare_and_split(begin, end, batch.builders[i]);
      build_part(begin, end, batch.builders[i], i == 0 ? batch.graph : batch.part_graphs[i]);
    });
    for (int i = 1; i < parts; ++i) append_graph(batch.part_graphs[i], batch.graph);
  }
  gather_targets(batch.graph, omit ? batch.kept_targets : batch.scene_targets, batch.targets,
                 batch.in_loss);
  if (weighs_bodies()) {
    gather_loss_weights(batch.graph, omit ? batch.kept_motion : batch.scene_motion,
                        trainer_config_.rest_loss_weight, trainer_config_.impact_loss_weight,
                        batch.loss_weights);
  }
}

void Trainer::push_forward_current() {
  PreparedBatch& batch = current();
  const int rounds = batch.scene_pushed.empty()
                         ? 0
                         : *std::max_element(batch.scene_pushed.begin(), batch.scene_pushed.end());
  if (rounds == 0) return;
  const auto start = std::chrono::steady_clock::now();
  const int h = config_.graph.history;
  const double correction = config_.noise_correction;
  // Each scene's first node in the batch graph, read before build_graph rewrites the graph
  // (its first part is rebuilt in place while the other parts advance their scenes).
  std::vector<int> scene_first_node(batch.scenes.size());
  // Round r advances every scene pushed more than r frames by one, to the frame r + 1 after the
  // one it was drawn at, so each reaches its own frame after its last round.
  for (int round = 0; round < rounds; ++round) {
    // The network's prediction for every scene of the batch as it stands, with the parameters
    // being optimised and no gradient.
    const ConstMatrixView output =
        backend_->forward(params_.data(), normalizers_, batch.graph, false);
    pushforward_accelerations_.resize(output.rows(), 3);
    normalizers_.target.denormalize(output, pushforward_accelerations_);
    for (size_t b = 0; b < scene_first_node.size(); ++b) {
      scene_first_node[b] = batch.graph.object_first_node[batch.graph.scene_first_object[b]];
    }
    // Each scene still being pushed advanced to its prediction, then turned after its last
    // round when random_yaw; in parallel parts like the first build.
    auto advance = [&](int begin, int end) {
      StepWorkspace workspace;
      std::vector<Pose> next;
      for (int b = begin; b < end; ++b) {
        const int steps = batch.scene_pushed[b];
        if (round >= steps) continue;
        Scene& scene = batch.scenes[b];
        const SampleRef& sample = batch.samples[b];
        if (config_.graph.omit_free_flight) {
          // The graph held the objects with a collision edge; the others fly free.
          const Trajectory& trajectory = data_[sample.trajectory];
          const Points kept_rows =
              pushforward_accelerations_
                  .middleRows(scene_first_node[b], batch.kept_scenes[b].num_nodes())
                  .cast<double>();
          batch.free_flight[b].expand_accelerations(
              scene, kept_rows, trajectory.gravity * trajectory.time_step * trajectory.time_step,
              workspace.accelerations);
        } else {
          workspace.accelerations =
              pushforward_accelerations_.middleRows(scene_first_node[b], scene.num_nodes())
                  .cast<double>();
        }
        integrate_next_poses(scene, next, workspace);
        const int frame = sample.frame - steps + round + 1;
        if (trainer_config_.pushforward_skips_rest) {
          const TrajectoryObject* truth = data_[sample.trajectory].objects.data();
          for (size_t o = 0; o < next.size(); ++o) {
            if (batch.scene_motion[b][o] == kResting) next[o] = truth[o].poses[frame];
          }
        }
        advance_to_predicted(data_[sample.trajectory], frame, h, next, correction, scene,
                             batch.scene_targets[b]);
        if (config_.random_yaw && round == steps - 1) {
          turn_about_vertical(batch.scene_yaw[b], scene, batch.scene_targets[b]);
        }
      }
    };
    build_graph(omp_get_max_threads(), batch, advance);
  }
  times_.pushforward += seconds_since(start);
}

void Trainer::predict_turned_current() {
  const auto start = std::chrono::steady_clock::now();
  const PreparedBatch& batch = current();
  const int scenes = static_cast<int>(batch.scenes.size());
  // One angle per scene from a generator of its own, seeded by the scene's noise seed: the
  // batch's other draws stay what they were without the term.
  std::vector<double>& angles = turned_.scene_yaw;
  angles.resize(scenes);
  for (int b = 0; b < scenes; ++b) {
    const std::uint64_t seed = batch.scene_seeds[b];
    std::seed_seq turn_seeds{static_cast<std::uint32_t>(seed),
                             static_cast<std::uint32_t>(seed >> 32), std::uint32_t{0x7e4d}};
    std::mt19937_64 turn(turn_seeds);
    angles[b] = std::uniform_real_distribution<double>(0.0, 2.0 * std::numbers::pi)(turn);
  }
  turned_.samples = batch.samples;
  turned_.scenes.resize(scenes);
  turned_.scene_targets.resize(scenes);
  turned_.scene_motion = batch.scene_motion;
  // The turned copies built into a graph of their own, as the batch was.
  build_graph(omp_get_max_threads(), turned_, [&](int begin, int end) {
    for (int b = begin; b < end; ++b) {
      turned_.scenes[b] = batch.scenes[b];
      turned_.scene_targets[b] = batch.scene_targets[b];
      turn_about_vertical(angles[b], turned_.scenes[b], turned_.scene_targets[b]);
    }
  });
  const ConstMatrixView output =
      backend_->forward(params_.data(), normalizers_, turned_.graph, false);
  turned_prediction_.resize(output.rows(), 3);
  normalizers_.target.denormalize(output, turned_prediction_);
  // Rows pair up where a scene has the same objects with the same nodes in both graphs (with
  // omit_free_flight, a turn could in principle change which bodies are near contact by rounding);
  // each such scene's rows are turned back by its angle, in the batch graph's order.
  const Graph& graph = batch.graph;
  const Graph& turned = turned_.graph;
  RowMatrixXf turned_back(graph.num_mesh_nodes(), 3);
  turned_back.setZero();
  turned_rows_.assign(graph.num_mesh_nodes(), 0);
  for (int b = 0; b < scenes && b < graph.num_scenes() && b < turned.num_scenes(); ++b) {
    const int objects = graph.scene_first_object[b + 1] - graph.scene_first_object[b];
    if (turned.scene_first_object[b + 1] - turned.scene_first_object[b] != objects) continue;
    const int first = graph.object_first_node[graph.scene_first_object[b]];
    const int turned_first = turned.object_first_node[turned.scene_first_object[b]];
    bool same = true;
    for (int o = 0; o <= objects && same; ++o) {
      same = graph.object_first_node[graph.scene_first_object[b] + o] - first ==
             turned.object_first_node[turned.scene_first_object[b] + o] - turned_first;
    }
    if (!same) continue;
    const int rows = graph.object_first_node[graph.scene_first_object[b + 1]] - first;
    // Rows are turned by v·Rᵀ, so v·R turns them back.
    const Eigen::Matrix3f back =
        Eigen::AngleAxisd(angles[b], Vec3::UnitZ()).toRotationMatrix().cast<float>();
    turned_back.middleRows(first, rows) = turned_prediction_.middleRows(turned_first, rows) * back;
    std::fill_n(turned_rows_.begin() + first, rows, std::uint8_t{1});
  }
  turned_prediction_.resize(graph.num_mesh_nodes(), 3);
  normalizers_.target.normalize(turned_back, turned_prediction_);
  times_.heading += seconds_since(start);
}

void Trainer::set_build_ahead(bool on) {
  if (on && !ahead_) ahead_ = std::make_unique<detail::BackgroundTask>();
  if (!on && ahead_) {
    // The batch in flight is dropped; what it threw too.
    ahead_counter_ = -1;
    ahead_.reset();
  }
}

bool Trainer::take_batch_built_ahead(std::int64_t counter) {
  if (ahead_counter_ < 0) return false;
  const std::int64_t built_for = std::exchange(ahead_counter_, -1);
  const auto start = std::chrono::steady_clock::now();
  ahead_->wait();
  // Built for another step number (a restore() or step_on() came in between): drawn anew.
  if (built_for != counter) return false;
  current_ = 1 - current_;
  times_.build += current().build_seconds;
  times_.build_waited += seconds_since(start);
  return true;
}

void Trainer::start_building_ahead(std::int64_t counter) {
  PreparedBatch& next = batches_[1 - current_];
  // This thread's OpenMP setting: the background thread's own is the process default.
  const int threads = omp_get_max_threads();
  ahead_->start([this, &next, counter, threads] { draw_and_build(counter, threads, next); });
  ahead_counter_ = counter;
}

void Trainer::clip_gradient() {
  double squares = 0.0;
  for (float g : grads_) squares += double(g) * g;
  const double norm = std::sqrt(squares);
  last_gradient_norm_ = norm;
  const float limit = trainer_config_.gradient_clip;
  if (limit <= 0.0f || norm <= limit) return;
  const float scale = static_cast<float>(limit / norm);
  for (float& g : grads_) g *= scale;
}

void Trainer::warm_up_statistics(int batches) {
  const auto start = std::chrono::steady_clock::now();
  const double steps_build = times_.build;
  for (int i = 0; i < batches; ++i) {
    // Counters from -1 down: apart from every training step's draws.
    build_current(-1 - static_cast<std::int64_t>(i));
    accumulate_statistics();
  }
  // Its batches are no step's: the per-step phases stay the steps' own.
  times_.build = steps_build;
  times_.warmup += seconds_since(start);
}

void Trainer::set_backend(std::unique_ptr<NetworkBackend> backend) {
  if (!backend) throw ConfigError("trainer: set_backend(nullptr)");
  backend_ = std::move(backend);
}

void Trainer::accumulate_statistics() {
  // Every process freezes at the same step: they all add the same sums.
  if (normalizers_.target.frozen()) return;
  // This batch's statistics (MeshGraphNets style: every input block, and the dynamic nodes'
  // targets), counted from zero, ...
  batch_statistics_ = network_.make_normalizers();
  const PreparedBatch& batch = current();
  network_.accumulate_input_statistics(batch.graph, batch_statistics_);
  RowMatrixXf dynamic_targets(std::count(batch.in_loss.begin(), batch.in_loss.end(), 1), 3);
  for (Eigen::Index i = 0, r = 0; i < batch.targets.rows(); ++i) {
    if (batch.in_loss[i]) dynamic_targets.row(r++) = batch.targets.row(i);
  }
  batch_statistics_.target.accumulate(dynamic_targets);
  // ... summed over processes in one flat buffer (count, sums, sums of squares per normaliser),
  statistics_buffer_.clear();
  for (Normalizer* n : all_of(batch_statistics_)) {
    statistics_buffer_.push_back(n->count());
    statistics_buffer_.insert(statistics_buffer_.end(), n->sum().begin(), n->sum().end());
    statistics_buffer_.insert(statistics_buffer_.end(), n->sum_squares().begin(),
                              n->sum_squares().end());
  }
  collective_->sum(statistics_buffer_);
  // ... and added: one accumulation per step, however many processes.
  size_t at = 0;
  for (Normalizer* n : all_of(normalizers_)) {
    const double count = statistics_buffer_[at++];
    const Eigen::Map<const Eigen::VectorXd> sum(&statistics_buffer_[at], n->size());
    const Eigen::Map<const Eigen::VectorXd> squares(&statistics_buffer_[at + n->size()], n->size());
    at += 2 * static_cast<size_t>(n->size());
    n->add(count, sum, squares);
  }
}

double Trainer::loss_and_gradient(bool with_gradient, bool reduce) {
  const PreparedBatch& batch = current();
  normalized_targets_.resize(batch.targets.rows(), 3);
  normalizers_.target.normalize(batch.targets, normalized_targets_);
  // The mean is over every process's dynamic nodes, counted before the network runs so that
  // each chunk of the batch can take its gradient as soon as its output exists.
  double count = static_cast<double>(std::count(batch.in_loss.begin(), batch.in_loss.end(), 1));
  if (reduce) collective_->sum(std::span<double>(&count, 1));
  if (count == 0) {
    // Nothing to learn from (every body of every scene left out): no step, not the last one's.
    if (with_gradient) {
      std::fill(grads_.begin(), grads_.end(), 0.0f);
      last_gradient_norm_ = 0.0;
    }
    last_heading_gap_ = 0.0;
    return 0.0;
  }
  // Squared error, or Huber's: quadratic within delta, linear beyond (scaled to match at 0).
  const double delta = trainer_config_.huber_delta;
  auto loss_of = [delta](double error) {
    const double size = std::abs(error);
    return delta <= 0.0 || size <= delta ? error * error : delta * (2.0 * size - delta);
  };
  auto slope_of = [delta](double error) {
    return delta <= 0.0 || std::abs(error) <= delta ? error : std::copysign(delta, error);
  };
  const float scale = 2.0f / static_cast<float>(3 * count);
  // With heading_consistency, the turned prediction as a second target of weight `consistency`
  // (predict_turned_current ran on this batch).
  const float consistency = with_gradient ? trainer_config_.heading_consistency : 0.0f;
  if (consistency > 0.0f) node_heading_gap_.assign(batch.targets.rows(), 0.0);
  // The loss of the output rows of nodes [first, first + rows), and its gradient when asked.
  const bool weighted = weighs_bodies();
  auto node_loss = [&](int first, const ConstMatrixRef& output, MatrixRef* d_output) {
    double squares = 0.0;
    if (d_output) d_output->setZero();
    for (Eigen::Index r = 0; r < output.rows(); ++r) {
      const Eigen::Index i = first + r;
      if (!batch.in_loss[i]) continue;
      const float weight = weighted ? batch.loss_weights[i] : 1.0f;
      for (int c = 0; c < 3; ++c) {
        const double error = output(r, c) - normalized_targets_(i, c);
        squares += weight * loss_of(error);
        if (d_output) (*d_output)(r, c) = scale * weight * slope_of(error);
      }
      if (consistency > 0.0f && turned_rows_[i]) {
        // Chunks run on several threads: each row's gap has its own slot, summed in row order.
        double gaps = 0.0;
        for (int c = 0; c < 3; ++c) {
          const float gap = output(r, c) - turned_prediction_(i, c);
          gaps += double(gap) * gap;
          (*d_output)(r, c) += scale * weight * consistency * gap;
        }
        node_heading_gap_[i] = weight * gaps;
      }
    }
    return squares;
  };
  double squares = 0.0;
  if (with_gradient) {
    std::fill(grads_.begin(), grads_.end(), 0.0f);
    squares = backend_->forward_backward(
        params_.data(), normalizers_, batch.graph, grads_.data(),
        [&](int first, const ConstMatrixRef& output, MatrixRef d_output) {
          return node_loss(first, output, &d_output);
        });
  } else {
    squares =
        node_loss(0, backend_->forward(params_.data(), normalizers_, batch.graph, false), nullptr);
  }
  double sums[2] = {squares, 0.0};
  if (consistency > 0.0f) {
    for (const double gap : node_heading_gap_) sums[1] += gap;
  }
  if (reduce) collective_->sum(std::span<double>(sums, 2));
  squares = sums[0];
  last_heading_gap_ = sums[1] / (3 * count);
  if (with_gradient) {
    // Each process's gradient is its part of the global mean's: their sum is the whole.
    if (reduce) collective_->sum(std::span<float>(grads_.data(), grads_.size()));
    clip_gradient();
  }
  return squares / (3 * count);
}

std::uint64_t Trainer::draw_batch(std::int64_t counter, std::vector<SampleRef>& batch) const {
  std::mt19937_64 generator = step_generator(counter);
  std::uniform_int_distribution<size_t> pick(0, samples_.size() - 1);
  batch.resize(static_cast<size_t>(local_batch_size(trainer_config_.batch_size)));
  for (SampleRef& sample : batch) sample = samples_[pick(generator)];
  return generator();
}

TrainStep Trainer::step() {
  const std::int64_t counter = adam_.step();
  if (!take_batch_built_ahead(counter)) build_current(counter);
  // The next step's batch depends only on its number: it is built while this one trains.
  if (ahead_) start_building_ahead(counter + 1);
  return train_on_current();
}

TrainStep Trainer::step_on(const std::vector<SampleRef>& samples, std::uint64_t noise_seed) {
  build_current(samples, std::mt19937_64(noise_seed));
  return train_on_current();
}

TrainStep Trainer::train_on_current() {
  push_forward_current();
  const auto statistics_start = std::chrono::steady_clock::now();
  accumulate_statistics();
  times_.statistics += seconds_since(statistics_start);
  // After the statistics: both predictions normalised alike.
  if (trainer_config_.heading_consistency > 0.0f) predict_turned_current();
  TrainStep result;
  result.learning_rate = adam_.learning_rate();
  auto start = std::chrono::steady_clock::now();
  result.loss = loss_and_gradient(true, true);
  result.gradient_norm = last_gradient_norm_;
  result.heading_gap = last_heading_gap_;
  times_.network += seconds_since(start);
  start = std::chrono::steady_clock::now();
  adam_.update(params_, grads_);
  update_average();
  backend_->parameters_changed();
  times_.optimizer += seconds_since(start);
  result.step = adam_.step();
  return result;
}

void Trainer::run(std::int64_t steps, const std::function<bool(const TrainStep&)>& on_step) {
  for (std::int64_t i = 0; i < steps; ++i) {
    const TrainStep result = step();
    if (on_step && !on_step(result)) return;
  }
}

double Trainer::evaluate_loss(const std::vector<SampleRef>& samples) {
  build_current(samples, step_generator(adam_.step()));
  push_forward_current();
  return loss_and_gradient(false, false);
}

void Trainer::update_average() {
  if (averaged_params_.empty()) return;
  const float decay = trainer_config_.weight_average, rate = 1.0f - decay;
  float* average = averaged_params_.data();
  const float* current = params_.data();
  // In Adam's fixed blocks, for the same reason (and the same bits for any thread count).
  detail::parallel_for_blocks(params_.size(), Adam::kParallelBlock, omp_get_max_threads(),
                              [=](size_t begin, size_t end) {
                                for (size_t i = begin; i < end; ++i) {
                                  average[i] = decay * average[i] + rate * current[i];
                                }
                              });
}

TrainerState Trainer::state() const {
  return {adam_.step(), adam_.first_moment(), adam_.second_moment(), "", averaged_params_};
}

void Trainer::restore(const TrainerState& state) {
  if (state.first_moment.size() != params_.size() || state.second_moment.size() != params_.size()) {
    throw ConfigError(fmt::format("trainer: optimizer state has {} and {} entries, the model {}",
                                  state.first_moment.size(), state.second_moment.size(),
                                  params_.size()));
  }
  adam_.first_moment() = state.first_moment;
  adam_.second_moment() = state.second_moment;
  adam_.set_step(state.step);
  // A run that turns the average on at a resume starts it from the parameters it resumes.
  if (averaged_params_.empty() || state.averaged_parameters.empty()) return;
  if (state.averaged_parameters.size() != params_.size()) {
    throw ConfigError(fmt::format("trainer: averaged parameters have {} entries, the model {}",
                                  state.averaged_parameters.size(), params_.size()));
  }
  averaged_params_ = state.averaged_parameters;
}

std::shared_ptr<const Model> Trainer::model() const {
  if (averaged_params_.empty()) return current_model();
  return std::make_shared<const Model>(config_, averaged_params_, normalizers_);
}

std::shared_ptr<const Model> Trainer::current_model() const {
  return std::make_shared<const Model>(config_, params_, normalizers_);
}

}  // namespace fignet
