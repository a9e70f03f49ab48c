// Training FIGNet on trajectories: batches of noisy samples concatenated into one graph, forward,
// MSE in normalised target space over dynamic nodes, backward, Adam. Deterministic for a given
// seed, thread count and process count. Data-parallel over a Collective: each process holds its
// share of the trajectories and draws its share of every global batch; statistics, the node
// count of the loss and the gradient are summed across processes, so Adam runs identically
// everywhere.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "fignet/graph/graph_builder.h"
#include "fignet/model/model.h"
#include "fignet/model/network_backend.h"
#include "fignet/nn/adam.h"
#include "fignet/rollout/free_flight.h"
#include "fignet/train/collective.h"
#include "fignet/train/training_batch.h"

namespace fignet {

namespace detail {
class BackgroundTask;
}

struct TrainerConfig {
  int batch_size = 4;  // scenes per step over all processes, concatenated into graphs
  AdamConfig adam;     // learning rate 1e-3 → 1e-4 over adam.decay_steps
  std::uint64_t seed = 1;
  // The gradient is scaled down to this global L2 norm when longer (0: never). One impact's
  // 10–25σ targets otherwise steer a whole step.
  float gradient_clip = 0.0f;
  // Huber loss on the normalised error with this threshold (0: mean squared error).
  float huber_delta = 0.0f;
  // Batches whose only use is the input and target statistics, before the first update of a new
  // run, so that early updates see settled normalisers.
  int statistics_warmup = 0;
  // Weight in the loss of the nodes of bodies at rest in the truth (resting_objects: no vertex
  // faster than kRestSpeed into and out of the sample's frame; 1: no different from the others).
  // Their targets are ~1e-3σ, so a bias that integrates to metres over a long rest costs the
  // unweighted loss almost nothing.
  float rest_loss_weight = 1.0f;
  // Weight in the loss of the nodes of bodies that undergo an impact in the truth at the sample's
  // frame (mark_impacts: the centre's acceleration departs from gravity by more than
  // kImpactG·g; 1: no different from the others). An eighth of the object-steps, they carry most
  // of the rollout error and come out too soft.
  float impact_loss_weight = 1.0f;
  // Share of the scenes replaced by their bodies held still in the air and let go
  // (make_still_sample_in_air), the gap under them drawn log-uniformly from kStillAirGaps (0:
  // none; trajectories with kinematic objects are never replaced). Their nodes weigh
  // rest_loss_weight like resting bodies': the two kinds of still body, told apart only by
  // what lies under them. A rest weight alone teaches that still bodies stay still in the air too.
  float still_air_fraction = 0.0f;
  // Decay of an exponential moving average of the parameters, updated after every step (0: none;
  // 0.999 averages over ~1000 steps). When on, the average is the model the run produces
  // (model(), validation, the --out file): it smooths the step-to-step noise that makes
  // successive checkpoints of one run differ by as much as recipes do.
  float weight_average = 0.0f;
  // Share of the steps whose scenes are pushed forward (the pushforward trick of Brandstetter et
  // al., 2022): each scene is drawn one frame earlier, the network predicts its next frame
  // without a gradient, and the step trains on the scene advanced to that prediction
  // (advance_to_predicted), so the model learns to correct the errors it makes itself, which a
  // rollout feeds it, besides the training noise (0: none). Scenes at the first frame with a
  // history and still bodies in the air are not pushed. Costs one forward pass and one graph
  // build more per pushed step.
  float pushforward_fraction = 0.0f;
  // In a pushed scene, bodies at rest in the data (the flag rest_loss_weight weighs) are
  // advanced to their true frame, not to the prediction: the push teaches the network its own
  // errors in motion and contact, not to correct a resting body's prediction by the loss's
  // largest weight. false: every dynamic body is pushed.
  bool pushforward_skips_rest = false;
  // Prediction steps of a pushed scene (1..kMaxPushforwardSteps): it is drawn this many frames
  // early (fewer where the trajectory's first frames leave no room) and rolled out to its frame
  // by the network, so the step trains on inputs with a short rollout's accumulated error, not
  // one step's. Each step more costs one forward pass and one graph build more per pushed step.
  int pushforward_steps = 1;
  // Weight in the loss of the squared difference between each dynamic node's prediction and the
  // prediction for the same scene turned about the vertical by a random angle and turned back,
  // which counts as a target, without a gradient (0: none). Physics does not change with the
  // heading; the network does, a little: `turns` averages that away at run time for turns× the
  // network's cost, this term trains it away. The difference is measured on the batch as trained
  // (after the push). Costs one graph build and one forward pass more per step.
  float heading_consistency = 0.0f;
};

inline constexpr int kMaxPushforwardSteps = 8;

// Everything besides the model that makes training continue exactly where it stopped: the
// optimizer's moments and step count. Sampling needs no state: each step's generator is seeded
// from (seed, process, step), so a resumed run draws what the uninterrupted one would have.
struct TrainerState {
  std::int64_t step = 0;
  std::vector<float> first_moment, second_moment;
  std::string rng;  // unused since sampling is counter-based; kept for older checkpoints
  // The parameters' moving average (empty when the run keeps none).
  std::vector<float> averaged_parameters;
};

// Wall-clock seconds spent in each phase of the steps so far (this process), to tell what bounds
// training: building graphs on the CPU, input statistics, the network's passes, or Adam.
struct TrainerTimes {
  double build = 0.0, statistics = 0.0, network = 0.0, optimizer = 0.0;
  // Of `build`, what the steps waited for batches built ahead (set_build_ahead); the rest of it
  // ran beside the step before.
  double build_waited = 0.0;
  double warmup = 0.0;  // the statistics warm-up's batches, apart from the steps' phases
  // The pushforward's own forward passes and graph builds (pushforward_fraction), apart from the
  // phases above.
  double pushforward = 0.0;
  // heading_consistency's graph builds and forward passes of the turned copies.
  double heading = 0.0;
};

struct TrainStep {
  std::int64_t step = 0;  // steps done, this one included
  double loss = 0.0;      // mean squared normalised error over the batch's dynamic nodes (weighted)
  float learning_rate = 0.0f;
  double gradient_norm = 0.0;  // global L2 norm of the gradient, before any clipping
  // With heading_consistency: the mean squared normalised difference between the batch's
  // predictions and those of its turned copy turned back, over the loss's nodes (weighted as the
  // loss); not part of `loss`, which stays the fit to the data.
  double heading_gap = 0.0;
};

class Trainer {
 public:
  // Trains a fresh model of `config` (or continues `initial`) on `data`, which must outlive it:
  // all the trajectories, or this process's share of them when `collective` spans several
  // processes (then every process must construct its Trainer alike, and `collective` outlive it).
  Trainer(const ModelConfig& config, const TrainerConfig& trainer_config,
          const std::vector<Trajectory>& data, const Model* initial = nullptr,
          Collective* collective = nullptr);
  // The backend holds on to network(): a trainer stays where it was made.
  Trainer(const Trainer&) = delete;
  Trainer& operator=(const Trainer&) = delete;
  ~Trainer();

  // One optimisation step on a random batch (this process's share of it).
  TrainStep step();
  // Accumulates the statistics of `batches` random batches without updating the parameters (a
  // new run's warm-up; the batches are drawn apart from those of the training steps).
  void warm_up_statistics(int batches);
  // One step on the given samples of this process's data, with noise from `noise_seed`: what
  // step() does after drawing them. Every process calls it together.
  TrainStep step_on(const std::vector<SampleRef>& samples, std::uint64_t noise_seed);
  // Runs `steps` steps; `on_step` sees each result and may stop early by returning false.
  void run(std::int64_t steps, const std::function<bool(const TrainStep&)>& on_step);
  // The loss of one batch of this process's data, without updating anything or communicating
  // (noise included, as in training).
  double evaluate_loss(const std::vector<SampleRef>& samples);

  // Runs the network's passes on `backend` (made for network()) from the next step on; the CPU
  // backend by default. Sampling, noise, statistics and Adam are unchanged.
  void set_backend(std::unique_ptr<NetworkBackend> backend);
  const NetworkBackend& backend() const { return *backend_; }
  // With `on`, step() builds the next step's batch on a thread of its own while this step runs
  // the network and Adam: for backends that run the passes off the CPU (a GPU), whose cores
  // would otherwise wait for the graphs. The batches and every bit of the run stay the same.
  // Off by default: beside the CPU backend the two would share the cores.
  void set_build_ahead(bool on);
  bool builds_ahead() const { return ahead_ != nullptr; }
  const Network& network() const { return network_; }

  // An immutable snapshot of the model this run produces: the parameters' moving average when
  // weight_average > 0, the parameters otherwise; with the current statistics.
  std::shared_ptr<const Model> model() const;
  // The same with the parameters being optimised (what a checkpoint holds to resume from).
  std::shared_ptr<const Model> current_model() const;
  std::int64_t steps_done() const { return adam_.step(); }
  const std::vector<SampleRef>& samples() const { return samples_; }
  // The last step's scenes and their target rows as it trained on them (after the pushforward),
  // and how many frames each was pushed forward (0: not pushed): for tests and debugging.
  const std::vector<Scene>& batch_scenes() const { return current().scenes; }
  const std::vector<Points>& batch_targets() const { return current().scene_targets; }
  const std::vector<std::uint8_t>& batch_pushed() const { return current().scene_pushed; }
  // With heading_consistency: the angle (radians, about the vertical) each scene of the last
  // step was turned by for the prediction it was held to; empty otherwise.
  const std::vector<double>& batch_heading_turns() const { return turned_.scene_yaw; }
  // The graph the last step trained on (with omit_free_flight, of the bodies in contact only).
  const Graph& batch_graph() const { return current().graph; }

  // Checkpoints: state() with model() captures training; restore() continues it exactly.
  TrainerState state() const;
  // Throws ConfigError when the state does not fit this trainer's parameter count.
  void restore(const TrainerState& state);
  const TrainerConfig& trainer_config() const { return trainer_config_; }

  const std::vector<float>& parameters() const { return params_; }
  const Adam& optimizer() const { return adam_; }
  const TrainerTimes& times() const { return times_; }
  const Normalizers& normalizers() const { return normalizers_; }
  // This process's share of a global batch of `batch` samples.
  int local_batch_size(int batch) const;

 private:
  // A batch ready for the network: its samples' scenes, the graph built from them and the loss's
  // inputs, with the scratch that built them. Two of them when building ahead: the step's own
  // and the next one's.
  struct PreparedBatch {
    std::vector<SampleRef> samples;  // what it was built from (draw_and_build's draw, or step_on's)
    std::vector<Scene> scenes;
    std::vector<Points> scene_targets;
    // Per scene, per object: what the body does in the truth (BodyMotion), only when a loss
    // weight is set or the push skips resting bodies.
    std::vector<std::vector<std::uint8_t>> scene_motion;
    std::vector<std::uint64_t> scene_seeds;
    // Per scene: how many frames early it was drawn to be pushed forward before the step
    // (pushforward_fraction, pushforward_steps; 0: not pushed), and its turn about the vertical
    // when random_yaw (applied after the push).
    std::vector<std::uint8_t> scene_pushed;
    std::vector<double> scene_yaw;
    // Batches are built by up to one builder per thread, each into its own part, then appended
    // in scene order.
    std::vector<GraphBuilder> builders;
    std::vector<Graph> part_graphs;
    // With omit_free_flight, per scene: which of its objects have a collision edge, and the scene,
    // targets and resting flags of those alone, which the graph is built from, with the split's
    // collision pairs (no second search).
    std::vector<FreeFlightSplit> free_flight;
    std::vector<Scene> kept_scenes;
    std::vector<SceneContacts> kept_contacts;
    std::vector<Points> kept_targets;
    std::vector<std::vector<std::uint8_t>> kept_motion;
    Graph graph;
    RowMatrixXf targets;
    std::vector<std::uint8_t> in_loss;
    std::vector<float> loss_weights;  // per node, only when weighs_bodies()
    double build_seconds = 0.0;       // what building it last took
  };

  // Builds `samples` into `batch` (noise from one seed per scene, drawn in order from `noise`),
  // in parallel parts on up to `threads` threads; with `may_push`, draws whether the batch is
  // pushed forward (its scenes then a frame early). Reads only the data and the configs: it may
  // run beside a step.
  void build_batch(const std::vector<SampleRef>& samples, std::mt19937_64 noise, bool may_push,
                   int threads, PreparedBatch& batch) const;
  // Draws the batch of draw number `counter` (draw_batch) into batch.samples and builds it.
  void draw_and_build(std::int64_t counter, int threads, PreparedBatch& batch) const;
  // build_batch, or draw_and_build, into the current batch on this thread's OpenMP threads.
  void build_current(const std::vector<SampleRef>& samples, std::mt19937_64 noise);
  void build_current(std::int64_t counter);
  // Makes the batch built ahead the current one when it was built for step number `counter`
  // (waiting for it); otherwise drops it. Returns whether it did.
  bool take_batch_built_ahead(std::int64_t counter);
  // Starts building the batch of step number `counter` into the other batch.
  void start_building_ahead(std::int64_t counter);
  // Builds the graph of batch.scenes in up to `threads` parts, each first running
  // `prepare_scenes(begin, end)` on its own run of scenes, then the targets and loss weights.
  void build_graph(int threads, PreparedBatch& batch,
                   const std::function<void(int, int)>& prepare_scenes) const;
  // Advances the current batch's pushed scenes to the network's own prediction of their next
  // frame and rebuilds its graph (pushforward_fraction); nothing when none is pushed.
  void push_forward_current();
  // The network's prediction for the current batch turned about the vertical by a random angle
  // per scene, turned back and normalised, into turned_prediction_ in the batch graph's row order,
  // with turned_rows_ marking the rows whose node is the same in both graphs
  // (heading_consistency).
  void predict_turned_current();
  // Statistics, forward, backward and Adam on the current batch.
  TrainStep train_on_current();
  PreparedBatch& current() { return batches_[current_]; }
  const PreparedBatch& current() const { return batches_[current_]; }
  // Adds this step's statistics of every input and of the targets, summed over processes.
  void accumulate_statistics();
  // Mean over every process's dynamic nodes; with `reduce`, counts and gradients are summed
  // over processes.
  double loss_and_gradient(bool with_gradient, bool reduce);
  bool weighs_bodies() const {
    return trainer_config_.rest_loss_weight != 1.0f || trainer_config_.impact_loss_weight != 1.0f;
  }
  // Whose samples carry the bodies' motion flags: those weighed in the loss or kept out of the
  // push.
  bool flags_motion() const { return weighs_bodies() || trainer_config_.pushforward_skips_rest; }
  // Scales grads_ to trainer_config_.gradient_clip when longer.
  void clip_gradient();
  // averaged_params_ ← d·averaged_params_ + (1 − d)·params_, d = weight_average.
  void update_average();
  std::mt19937_64 step_generator(std::int64_t step) const;
  // Fills `batch` with this process's share of the batch of draw number `counter` (a step's
  // number; warm-up batches count from -1 down) and returns the batch's noise seed.
  std::uint64_t draw_batch(std::int64_t counter, std::vector<SampleRef>& batch) const;

  ModelConfig config_;
  TrainerConfig trainer_config_;
  const std::vector<Trajectory>& data_;
  Network network_;
  std::vector<float> params_;
  std::vector<float> averaged_params_;  // empty unless weight_average > 0
  AlignedFloats grads_;  // aligned: reductions into it then sum in an address-independent order
  Normalizers normalizers_;
  Adam adam_;
  Collective* collective_;
  std::vector<SampleRef> samples_;
  std::unique_ptr<NetworkBackend> backend_;
  // Scratch reused every step.
  std::array<PreparedBatch, 2> batches_;
  int current_ = 0;
  RowMatrixXf normalized_targets_;
  RowMatrixXf pushforward_accelerations_;
  PreparedBatch turned_;  // the current batch turned (heading_consistency)
  RowMatrixXf turned_prediction_;
  std::vector<std::uint8_t> turned_rows_;
  std::vector<double> node_heading_gap_;  // per row, summed in row order after the passes
  double last_heading_gap_ = 0.0;
  Normalizers batch_statistics_;
  std::vector<double> statistics_buffer_;
  TrainerTimes times_;
  double last_gradient_norm_ = 0.0;
  // The step number whose batch is being built ahead into the other batch (-1: none), and the
  // thread that builds it (null unless set_build_ahead). Last: it finishes before the batches go.
  std::int64_t ahead_counter_ = -1;
  std::unique_ptr<detail::BackgroundTask> ahead_;
};

}  // namespace fignet
