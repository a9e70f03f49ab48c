#include "fignet/rollout/predictor.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fignet/error.h"

namespace fignet {

bool familiar_material(const StaticProperties& body, const ModelConfig& config) {
  return config.friction.holds(body.friction) && config.restitution.holds(body.restitution);
}

bool familiar_floor(const Floor& floor, const ModelConfig& config) {
  return config.floor_friction.holds(floor.properties.friction) &&
         config.floor_restitution.holds(floor.properties.restitution);
}

double mass_fit_factor(const Scene& scene, double min_mass, double max_mass) {
  if (!(min_mass > 0.0 && max_mass >= min_mass)) return 1.0;
  // The scene's dynamic masses as a span of logarithms.
  MassRange masses;
  masses.add(scene.objects);
  if (masses.empty() || !std::isfinite(masses.heaviest)) return 1.0;
  // The least shift that lifts the lightest in, and the most that keeps the heaviest in.
  const double low = std::log(min_mass) - std::log(masses.lightest);
  const double high = std::log(max_mass) - std::log(masses.heaviest);
  // The shift nearest 0 that fits the span inside; centred on the range when it does not fit.
  const double shift = low <= high ? std::clamp(0.0, low, high) : 0.5 * (low + high);
  return shift == 0.0 ? 1.0 : std::exp(shift);
}

void PredictionOptions::validate() const {
  if (threads < 0) {
    throw ConfigError(fmt::format("PredictionOptions: {} threads (must be >= 0)", threads));
  }
  if (turns < 1) {
    throw ConfigError(fmt::format("PredictionOptions: {} turns (must be >= 1; 1: off)", turns));
  }
}

ModelPredictor::ModelPredictor(std::shared_ptr<const Model> model, const PredictionOptions& options)
    : model_(std::move(model)), options_(options), builder_(model_->config().graph) {
  options.validate();
}

int ModelPredictor::turn_threads() const {
  const int threads = options_.threads > 0 ? options_.threads : Eigen::nbThreads();
  return std::min(threads, options_.copies());
}

template <typename Build>
void ModelPredictor::predict_averaged(const Scene& scene, Build&& build, Points& accelerations) {
  const int copies = options_.copies();
  if (options_.mirror) update_mirrors(scene);
  if (copies > 1 && turn_threads() > 1) {
    predict_turns_in_parallel(scene, build, accelerations);
    return;
  }
  // The turned and mirrored scenes first, so that last_graph() is the scene's own.
  for (int k = 1; k < copies; ++k) {
    make_copy(k, scene, turned_);
    build(turned_, builder_, graph_);
    run_network(turned_, turned_accelerations_);
    add_turned_back(k, turned_accelerations_);
  }
  build(scene, builder_, graph_);
  run_network(scene, accelerations);
  if (copies > 1) accelerations = (accelerations + turned_sum_) / copies;
}

template <typename Build>
void ModelPredictor::predict_turns_in_parallel(const Scene& scene, Build& build,
                                               Points& accelerations) {
  const int copies = options_.copies();
  while (static_cast<int>(copies_.size()) < copies - 1) {
    copies_.push_back(std::make_unique<TurnedCopy>(model_->config().graph));
  }
  copy_errors_.resize(copies);
  // Copy 0 is the scene itself, on the predictor's own builder and graph (last_graph()); inside
  // the parallel loop every product runs on its calling thread alone (gemm.h).
#pragma omp parallel for num_threads(turn_threads()) schedule(dynamic, 1)
  for (int k = 0; k < copies; ++k) {
    try {
      if (k == 0) {
        build(scene, builder_, graph_);
        run_network_on(scene, graph_, workspace_, denormalized_, accelerations);
      } else {
        TurnedCopy& copy = *copies_[k - 1];
        make_copy(k, scene, copy.scene);
        build(copy.scene, copy.builder, copy.graph);
        run_network_on(copy.scene, copy.graph, copy.workspace, copy.denormalized,
                       copy.accelerations);
      }
    } catch (...) {
      copy_errors_[k] = std::current_exception();
    }
  }
  for (std::exception_ptr& error : copy_errors_) {
    if (!error) continue;
    const std::exception_ptr first = error;
    std::fill(copy_errors_.begin(), copy_errors_.end(), nullptr);
    std::rethrow_exception(first);
  }
  // Mapped back and summed in the order of the one-thread path, so both give the same sums.
  for (int k = 1; k < copies; ++k) add_turned_back(k, copies_[k - 1]->accelerations);
  accelerations = (accelerations + turned_sum_) / copies;
}

Eigen::Matrix3d ModelPredictor::copy_map(int k) const {
  const double angle = 2.0 * std::numbers::pi * (k % options_.turns) / options_.turns;
  Eigen::Matrix3d map = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  if (k >= options_.turns) map.col(1) = -map.col(1);  // R·diag(1, −1, 1): reflect, then turn
  return map;
}

void ModelPredictor::make_copy(int k, const Scene& scene, Scene& copy) const {
  copy = scene;  // copy-assigned: a steady-state step reuses the last one's buffers
  map_about_vertical(copy_map(k), copy);
  if (k < options_.turns) return;
  for (size_t o = 0; o < copy.objects.size(); ++o) copy.objects[o].mesh = object_mirrors_[o];
}

void ModelPredictor::update_mirrors(const Scene& scene) {
  object_mirrors_.clear();
  for (const SceneObject& object : scene.objects) {
    const TriangleMesh& mesh = *object.mesh;
    auto entry = std::find_if(mirrors_.begin(), mirrors_.end(),
                              [&](const auto& e) { return e.first == &mesh; });
    // A mesh freed and another made at its address is told apart by its vertices and faces.
    auto mirrors = [&](const TriangleMesh& mirror) {
      return mirror.vertices().rows() == mesh.vertices().rows() &&
             mirror.faces().rows() == mesh.faces().rows() &&
             mirror.vertices().col(0) == mesh.vertices().col(0) &&
             mirror.vertices().col(1) == -mesh.vertices().col(1) &&
             mirror.vertices().col(2) == mesh.vertices().col(2) &&
             mirror.faces().col(0) == mesh.faces().col(0) &&
             mirror.faces().col(1) == mesh.faces().col(2) &&
             mirror.faces().col(2) == mesh.faces().col(1);
    };
    if (entry == mirrors_.end()) {
      entry = mirrors_.emplace(mirrors_.end(), &mesh, nullptr);
    }
    if (!entry->second || !mirrors(*entry->second)) {
      entry->second = std::make_unique<const TriangleMesh>(mirrored_mesh(mesh));
    }
    object_mirrors_.push_back(entry->second.get());
  }
  // Bodies come and go (a world's spawner): the mirrors of meshes no longer seen are let go once
  // they outnumber the scene's own (the scene's own, in object_mirrors_, stay where they are).
  if (mirrors_.size() > 2 * scene.objects.size() + 16) {
    std::erase_if(mirrors_, [&](const auto& entry) {
      return std::none_of(scene.objects.begin(), scene.objects.end(),
                          [&](const SceneObject& object) { return object.mesh == entry.first; });
    });
  }
}

void ModelPredictor::add_turned_back(int k, const Points& turned) {
  // Row vectors mapped by a ↦ a·Mᵀ map back by a ↦ a·M (M orthogonal).
  const Eigen::Matrix3d map = copy_map(k);
  if (k == 1) {
    turned_sum_.noalias() = turned * map;
  } else {
    turned_sum_.noalias() += turned * map;
  }
}

const Scene& ModelPredictor::with_fitted_masses(const Scene& scene) {
  if (!options_.fit_masses) return scene;
  const ModelConfig& config = model_->config();
  const double factor = mass_fit_factor(scene, config.min_mass, config.max_mass);
  if (factor == 1.0) return scene;
  mass_fitted_ = scene;  // copy-assigned: a steady-state step reuses the last one's buffers
  for (SceneObject& object : mass_fitted_.objects) {
    if (!object.kinematic) object.properties.mass *= factor;
  }
  return mass_fitted_;
}

void ModelPredictor::predict(const Scene& scene, Points& accelerations) {
  predict_objects(with_fitted_masses(scene), nullptr, nullptr, accelerations);
}

void ModelPredictor::predict_with_candidates(const Scene& scene,
                                             std::span<const ObjectPair> candidates,
                                             Points& accelerations) {
  predict_objects(with_fitted_masses(scene), &candidates, nullptr, accelerations);
}

void ModelPredictor::predict_with_search(const Scene& scene, std::span<const ObjectPair> candidates,
                                         std::span<const char> interacting,
                                         const SceneContacts& contacts, Points& accelerations) {
  // Fitted masses move no face: the search stands for the fitted copy too.
  const Search search{interacting, contacts};
  predict_objects(with_fitted_masses(scene), &candidates, &search, accelerations);
}

void ModelPredictor::predict_objects(const Scene& scene,
                                     const std::span<const ObjectPair>* candidates,
                                     const Search* search, Points& accelerations) {
  // A model trained on bodies in contact only sees those, and so does one asked to; the others
  // fall outside it.
  const bool omit = options_.free_flight || model_->config().graph.omit_free_flight;
  if (omit && search) {
    free_flight_.split_searched(scene, search->interacting, search->contacts, candidates, kept_,
                                kept_contacts_);
  } else if (omit) {
    free_flight_.split(builder_, scene, candidates, kept_, kept_contacts_);
  }
  const std::span<const ObjectPair> pairs =
      !candidates ? std::span<const ObjectPair>()
                  : (omit ? free_flight_.kept_candidates() : *candidates);
  // A turn about the vertical moves no object into or out of a pair: the candidates stand. The
  // kept scene itself is built from the split's search, and the whole scene from the caller's; a
  // turned copy meets the floor's faces elsewhere and is searched.
  auto build = [&](const Scene& s, GraphBuilder& builder, Graph& graph) {
    if (&s == &kept_) {
      builder.build_with_contacts(std::span(&kept_, 1), std::span(&kept_contacts_, 1), graph);
    } else if (search && &s == &scene) {
      builder.build_with_contacts(std::span(&scene, 1), std::span(&search->contacts, 1), graph);
    } else if (candidates) {
      builder.build_with_candidates(s, pairs, graph);
    } else {
      builder.build(s, graph);
    }
  };
  if (!omit) {
    predict_averaged(scene, build, accelerations);
    return;
  }
  if (kept_.objects.empty()) {
    build(kept_, builder_, graph_);  // nothing for the network: last_graph() says so
    kept_accelerations_.resize(0, 3);
  } else {
    predict_averaged(kept_, build, kept_accelerations_);
  }
  const ModelConfig& config = model_->config();
  free_flight_.expand_accelerations(scene, kept_accelerations_,
                                    config.gravity * config.time_step * config.time_step,
                                    accelerations);
}

void ModelPredictor::run_network(const Scene& scene, Points& accelerations) {
  // Eigen's thread count is process-wide: set ours for the forward pass, then give it back.
  const int previous = Eigen::nbThreads();
  if (options_.threads > 0) Eigen::setNbThreads(options_.threads);
  run_network_on(scene, graph_, workspace_, denormalized_, accelerations);
  Eigen::setNbThreads(previous);
}

void ModelPredictor::run_network_on(const Scene& scene, const Graph& graph,
                                    NetworkWorkspace& workspace, RowMatrixXf& denormalized,
                                    Points& accelerations) const {
  const ConstMatrixView normalized = model_->network().forward(
      model_->parameters().data(), model_->normalizers(), graph, workspace, false);
  // The scene's objects come first in the graph; a mesh floor's nodes follow and are dropped.
  const Eigen::Index n = scene.num_nodes();
  denormalized.resize(n, 3);
  model_->normalizers().target.denormalize(normalized.topRows(n), denormalized);
  accelerations = denormalized.cast<double>();
}

void GravityPredictor::predict(const Scene& scene, Points& accelerations) {
  accelerations.resize(scene.num_nodes(), 3);
  accelerations.rowwise() = step_acceleration_.transpose();
}

}  // namespace fignet
