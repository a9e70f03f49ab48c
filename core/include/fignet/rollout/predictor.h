// Anything that predicts per-node accelerations for a scene: a FIGNet model, or a stand-in (exact
// gravity, constant velocity) for baselines and tests. Rollouts and the Bullet world use this
// interface, so they run the same code path whatever predicts.
#pragma once

#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <span>

#include "fignet/graph/graph_builder.h"
#include "fignet/model/model.h"
#include "fignet/rollout/free_flight.h"

namespace fignet {

class AccelerationPredictor {
 public:
  virtual ~AccelerationPredictor() = default;
  // Positions of how many past frames the predictor needs besides the current one.
  virtual int history() const = 0;
  // One row per node of scene.objects, in order: the finite-difference acceleration
  // x^{t+1} − 2x^t + x^{t−1} in metres (rows of kinematic objects are ignored by callers).
  virtual void predict(const Scene& scene, Points& accelerations) = 0;
  // As predict(), with the object pairs to examine for contacts given by the caller (a physics
  // engine's broadphase; the floor, when a mesh, is object scene.objects.size()). Predictors
  // without a contact graph ignore them.
  virtual void predict_with_candidates(const Scene& scene, std::span<const ObjectPair> candidates,
                                       Points& accelerations) {
    (void)candidates;
    predict(scene, accelerations);
  }
  // As predict_with_candidates(), with the contact search of `scene` among those candidates that
  // the caller has made already (GraphBuilder::find_interacting_objects with the predictor's
  // graph config: its per-object flags and collision pairs), so that it is not made again.
  // Predictors without a contact graph ignore it.
  virtual void predict_with_search(const Scene& scene, std::span<const ObjectPair> candidates,
                                   std::span<const char> interacting, const SceneContacts& contacts,
                                   Points& accelerations) {
    (void)interacting;
    (void)contacts;
    predict_with_candidates(scene, candidates, accelerations);
  }
  // Face–face edges of the last prediction's graph (0 for predictors without a graph).
  virtual int last_face_edges() const { return 0; }
};

// How a ModelPredictor runs its model.
struct PredictionOptions {
  // Threads for Eigen's matrix products, or with turns > 1 for the turned copies, one per thread
  // (0: Eigen's default, every core). One by default: a step's products are small, and threads
  // that wait for a core another program holds stall each product by a scheduler time slice,
  // which made steps many times slower on a busy machine.
  int threads = 1;
  // Predict the scene `turns` times, turned by k/turns of a full turn about the vertical
  // (k = 0 … turns − 1), and average the predictions turned back. True accelerations turn with
  // the scene, so the average keeps what the predictions agree on and cancels horizontal
  // accelerations the model adds whatever the scene's heading: trained models carry a bias of
  // ~0.15 mm/step² in a direction of their own (docs/training-study.md) that slides resting
  // bodies sideways. 2 (a half turn) cancels a constant bias; 4 also what changes with the
  // heading as cos θ or sin θ. Costs `turns` predictions; 1: off. With threads other than 1
  // the turned copies run on separate threads, one copy per thread, each on one thread's
  // products: a one-scene step's products are too small to share well.
  int turns = 1;
  // Also predict the scene seen in a mirror, at each of the turns: reflected through the vertical
  // plane y = const through the floor's centre, every body's mesh mirrored (mirrored_mesh), and
  // the predictions reflected back into the average. Gravity, contact and friction act the same
  // in a mirror, so a true prediction is unchanged; the model's errors that have a handedness
  // (a spin it adds, a sideways slide at contact) cancel. Costs 2·turns predictions.
  bool mirror = false;
  // Present the network the scene's dynamic masses times one common factor, the one nearest 1
  // that brings them within the model's training masses (ModelConfig::min_mass, max_mass; a scene
  // whose masses span more than those gets the factor that centres its span on theirs, in
  // logarithms). Gravity and rigid contact move bodies the same whatever the common scale of
  // their masses; the network has seen only its data's: a 1000 kg cube is 17× MOVi-A's heaviest
  // body, and a pile of such bodies scattered tens of metres (docs/bullet-world.md). A scene
  // within the training masses is untouched; so is every scene of a model without them.
  bool fit_masses = true;
  // Bodies without a collision edge move in free flight (free_flight.h), outside the network, as
  // FIGNetDynamicsWorld moves them. Always so for a model trained with
  // GraphConfig::omit_free_flight, which never learned free flight; for another model, what its
  // rollouts would be in the world's hands (`fignet eval --free-flight`).
  bool free_flight = false;

  // Throws ConfigError naming the field that is out of range.
  void validate() const;
  // How many predictions each step averages: turns, twice that with mirror.
  int copies() const { return mirror ? 2 * turns : turns; }
};

// The lightest and heaviest dynamic body seen, kg (kinematic and massless bodies left out: their
// mass moves nothing). What `fignet train` records and what fit_masses compares it with.
struct MassRange {
  double lightest = INFINITY, heaviest = 0.0;
  bool empty() const { return !(heaviest > 0.0); }
  // Widens the range by `objects` (SceneObjects or TrajectoryObjects).
  template <class Objects>
  void add(const Objects& objects) {
    for (const auto& object : objects) {
      if (object.kinematic || !(object.properties.mass > 0.0)) continue;
      lightest = std::min(lightest, object.properties.mass);
      heaviest = std::max(heaviest, object.properties.mass);
    }
  }
};

// The factor PredictionOptions::fit_masses applies to the dynamic masses of `scene` for a model
// trained on masses in [min_mass, max_mass] kg: 1 when they lie within, when the scene has no
// dynamic body, or when the range is unknown (0).
double mass_fit_factor(const Scene& scene, double min_mass, double max_mass);

// Whether a body's material, or a floor's, lies within the model's training data's (ModelConfig's
// ranges; an unknown range holds every value). Outside them the model guesses.
bool familiar_material(const StaticProperties& body, const ModelConfig& config);
bool familiar_floor(const Floor& floor, const ModelConfig& config);

// Runs a FIGNet model: builds the graph, runs the network, un-normalises. One per thread. A model
// trained with GraphConfig::omit_free_flight sees only the objects with a collision edge; the
// others get their free-flight accelerations (free_flight.h).
class ModelPredictor : public AccelerationPredictor {
 public:
  ModelPredictor(std::shared_ptr<const Model> model, const PredictionOptions& options);
  explicit ModelPredictor(std::shared_ptr<const Model> model, int threads = 1)
      : ModelPredictor(std::move(model), PredictionOptions{.threads = threads}) {}
  int history() const override { return model_->config().graph.history; }
  void predict(const Scene& scene, Points& accelerations) override;
  void predict_with_candidates(const Scene& scene, std::span<const ObjectPair> candidates,
                               Points& accelerations) override;
  void predict_with_search(const Scene& scene, std::span<const ObjectPair> candidates,
                           std::span<const char> interacting, const SceneContacts& contacts,
                           Points& accelerations) override;
  int last_face_edges() const override { return graph_.face_edges.size(); }
  // The graph of the last prediction (for edge counts and debug drawing).
  const Graph& last_graph() const { return graph_; }
  const GraphBuilder& builder() const { return builder_; }

 private:
  // What one turned copy of the scene needs of its own when the copies run on separate threads.
  struct TurnedCopy {
    explicit TurnedCopy(const GraphConfig& config) : builder(config) {}
    Scene scene;
    GraphBuilder builder;
    Graph graph;
    NetworkWorkspace workspace;
    RowMatrixXf denormalized;
    Points accelerations;
  };
  // Runs the network on graph_ and un-normalises the scene's node rows.
  void run_network(const Scene& scene, Points& accelerations);
  // The same on a given graph and workspace, on the calling thread's share of the products.
  void run_network_on(const Scene& scene, const Graph& graph, NetworkWorkspace& workspace,
                      RowMatrixXf& denormalized, Points& accelerations) const;
  // Threads the turned copies may run on at once (1: one after another).
  int turn_threads() const;
  // Copy k's map of the scene (k < copies()): k mod turns of a turns-th of a full turn about the
  // vertical, after a reflection y ↦ −y for the mirrored copies (k >= turns).
  Eigen::Matrix3d copy_map(int k) const;
  // Makes `copy` scene's copy k: the scene mapped by copy_map(k), with mirrored meshes for k >=
  // turns (object_mirrors_, which update_mirrors() has filled for the scene).
  void make_copy(int k, const Scene& scene, Scene& copy) const;
  // Makes mirrors_ hold the mirror of each of the scene's meshes (kept from step to step), and
  // object_mirrors_ point to each object's.
  void update_mirrors(const Scene& scene);
  // Adds copy k's accelerations, mapped back, to turned_sum_ (copy 1 starts it).
  void add_turned_back(int k, const Points& turned);
  // Builds the graph with `build`, runs the network and, with turns > 1, averages over turns.
  template <typename Build>
  void predict_averaged(const Scene& scene, Build&& build, Points& accelerations);
  // predict_averaged's turns on turn_threads() threads, one copy per thread at a time.
  template <typename Build>
  void predict_turns_in_parallel(const Scene& scene, Build& build, Points& accelerations);
  // The scene the network sees: `scene` itself, or its copy with fitted masses (fit_masses).
  const Scene& with_fitted_masses(const Scene& scene);
  // A contact search the caller made (predict_with_search).
  struct Search {
    std::span<const char> interacting;
    const SceneContacts& contacts;
  };
  // predict_averaged on the whole scene, or on its objects with a collision edge only
  // (omit_free_flight or PredictionOptions::free_flight), the others in free flight. The scene's
  // own graph comes from `search` when given (it was made among `candidates`).
  void predict_objects(const Scene& scene, const std::span<const ObjectPair>* candidates,
                       const Search* search, Points& accelerations);

  std::shared_ptr<const Model> model_;
  PredictionOptions options_;
  GraphBuilder builder_;
  Graph graph_;
  NetworkWorkspace workspace_;
  RowMatrixXf denormalized_;
  Scene turned_, mass_fitted_;
  Points turned_accelerations_, turned_sum_;
  std::vector<std::unique_ptr<TurnedCopy>> copies_;  // copies() − 1, when turn_threads() > 1
  // Each mesh of the scenes seen so far with its mirror, for the mirrored copies.
  std::vector<std::pair<const TriangleMesh*, std::unique_ptr<const TriangleMesh>>> mirrors_;
  std::vector<const TriangleMesh*> object_mirrors_;  // the mirror of each object's mesh, in order
  std::vector<std::exception_ptr> copy_errors_;      // what each copy's thread threw
  FreeFlightSplit free_flight_;
  Scene kept_;                   // the scene's objects with a collision edge (omit_free_flight)
  SceneContacts kept_contacts_;  // and their collision pairs, as the split's search found them
  Points kept_accelerations_;
};

// Exact free fall: every node accelerates by gravity·dt² (the ballistic baseline without
// collisions; with h >= 1 the history supplies the velocity).
class GravityPredictor : public AccelerationPredictor {
 public:
  GravityPredictor(const Vec3& gravity, double time_step, int history = 2)
      : step_acceleration_(gravity * time_step * time_step), history_(history) {}
  int history() const override { return history_; }
  void predict(const Scene& scene, Points& accelerations) override;

 private:
  Vec3 step_acceleration_;
  int history_;
};

}  // namespace fignet
