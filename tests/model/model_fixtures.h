// Models for tests that need a network's answer, not a trained one.
#pragma once

#include <memory>
#include <random>

#include "fignet/graph/graph_builder.h"
#include "fignet/model/model.h"

namespace fignet::testing {

// A model of `config` with random weights and normalisers fitted to `scene`, so that neither is
// at its symmetric initial value.
inline std::shared_ptr<const Model> random_model(const Scene& scene, const ModelConfig& config) {
  Model fresh(config);
  std::vector<float> params = fresh.parameters();
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.0f, 0.2f);
  for (float& p : params) p += noise(rng);
  Normalizers normalizers = fresh.normalizers();
  Graph graph;
  GraphBuilder(config.graph).build(scene, graph);
  normalizers.mesh_node.accumulate(graph.mesh_nodes.matrix());
  normalizers.face_edge.accumulate(graph.face_edges.features.matrix());
  return std::make_shared<const Model>(config, params, normalizers);
}

}  // namespace fignet::testing
