#include "fignet/model/model.h"

#include <fmt/format.h>

#include "fignet/error.h"

namespace fignet {

Model::Model(const ModelConfig& config)
    : network_(config), normalizers_(network_.make_normalizers()) {
  network_.layout().initialize(parameters_, config.seed);
}

Model::Model(const ModelConfig& config, std::vector<float> parameters, Normalizers normalizers)
    : network_(config), parameters_(std::move(parameters)), normalizers_(std::move(normalizers)) {
  if (parameters_.size() != network_.layout().size()) {
    throw ConfigError(fmt::format("model: {} parameters given, the config needs {}",
                                  parameters_.size(), network_.layout().size()));
  }
  const Normalizers expected = network_.make_normalizers();
  auto check = [](const Normalizer& got, const Normalizer& want, const char* name) {
    if (got.size() != want.size()) {
      throw ConfigError(fmt::format("model: normaliser '{}' has {} columns, the config needs {}",
                                    name, got.size(), want.size()));
    }
  };
  check(normalizers_.mesh_node, expected.mesh_node, "mesh_node");
  check(normalizers_.object_node, expected.object_node, "object_node");
  check(normalizers_.face_edge, expected.face_edge, "face_edge");
  check(normalizers_.target, expected.target, "target");
  if (normalizers_.edges.size() != expected.edges.size()) {
    throw ConfigError("model: wrong number of edge normalisers for the config");
  }
  for (size_t t = 0; t < expected.edges.size(); ++t) {
    check(normalizers_.edges[t], expected.edges[t], "edge");
  }
}

}  // namespace fignet
