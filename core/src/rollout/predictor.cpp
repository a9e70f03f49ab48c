#include "fignet/rollout/predictor.h"

#include <fmt/format.h>

#include "fignet/error.h"

namespace fignet {

namespace {

Eigen::Index count_nodes(const Scene& scene) {
  Eigen::Index n = 0;
  for (const SceneObject& object : scene.objects) n += object.mesh->num_vertices();
  return n;
}

}  // namespace

ModelPredictor::ModelPredictor(std::shared_ptr<const Model> model, int threads)
    : model_(std::move(model)), builder_(model_->config().graph), threads_(threads) {
  if (threads < 0) {
    throw ConfigError(fmt::format("ModelPredictor: {} threads (must be >= 0)", threads));
  }
}

void ModelPredictor::predict(const Scene& scene, Points& accelerations) {
  builder_.build(scene, graph_);
  run_network(scene, accelerations);
}

void ModelPredictor::predict_with_candidates(const Scene& scene,
                                             std::span<const ObjectPair> candidates,
                                             Points& accelerations) {
  builder_.build_with_candidates(scene, candidates, graph_);
  run_network(scene, accelerations);
}

void ModelPredictor::run_network(const Scene& scene, Points& accelerations) {
  // Eigen's thread count is process-wide: set ours for the forward pass, then give it back.
  const int previous = Eigen::nbThreads();
  if (threads_ > 0) Eigen::setNbThreads(threads_);
  const ConstMatrixView normalized = model_->network().forward(
      model_->parameters().data(), model_->normalizers(), graph_, workspace_, false);
  Eigen::setNbThreads(previous);
  // The scene's objects come first in the graph; a mesh floor's nodes follow and are dropped.
  const Eigen::Index n = count_nodes(scene);
  denormalized_.resize(n, 3);
  model_->normalizers().target.denormalize(normalized.topRows(n), denormalized_);
  accelerations = denormalized_.cast<double>();
}

void GravityPredictor::predict(const Scene& scene, Points& accelerations) {
  accelerations.resize(count_nodes(scene), 3);
  accelerations.rowwise() = step_acceleration_.transpose();
}

}  // namespace fignet
