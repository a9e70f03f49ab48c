// The FIGNet input graph in flat storage: one feature matrix and index arrays per node and edge
// type, ready for batched matrix products. A batch of scenes is one graph with offset indices.
// Buffers keep their capacity across builds, so rebuilding a graph of similar size allocates
// nothing.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fignet/geometry/types.h"

namespace fignet {

// A row-major float matrix that grows by rows and keeps its capacity when cleared.
class FeatureMatrix {
 public:
  void reset(int cols) {
    cols_ = cols;
    rows_ = 0;
    data_.clear();
  }
  // Appends `count` rows and returns a pointer to the first of them (left uninitialised).
  float* append_rows(int count) {
    data_.resize(data_.size() + static_cast<size_t>(count) * cols_);
    rows_ += count;
    return data_.data() + data_.size() - static_cast<size_t>(count) * cols_;
  }
  int rows() const { return rows_; }
  int cols() const { return cols_; }
  const float* row(int r) const { return data_.data() + static_cast<size_t>(r) * cols_; }
  Eigen::Map<const RowMatrixXf> matrix() const { return {data_.data(), rows_, cols_}; }
  Eigen::Map<RowMatrixXf> matrix() { return {data_.data(), rows_, cols_}; }

 private:
  AlignedFloats data_;
  int rows_ = 0, cols_ = 0;
};

// Directed edges between two node sets, one sender and one receiver per edge.
struct EdgeSet {
  std::vector<std::int32_t> senders, receivers;
  FeatureMatrix features;
  int size() const { return static_cast<int>(receivers.size()); }
  void reset(int feature_size) {
    senders.clear();
    receivers.clear();
    features.reset(feature_size);
  }
};

// Face–face hyper-edges: three sender and three receiver mesh nodes per edge, each triplet
// sorted by the nodes' distance to their face's closest point (seed C.1.1).
struct FaceEdgeSet {
  std::vector<std::int32_t> senders, receivers;  // 3 per edge
  FeatureMatrix features;
  int size() const { return static_cast<int>(receivers.size() / 3); }
  void reset(int feature_size) {
    senders.clear();
    receivers.clear();
    features.reset(feature_size);
  }
};

struct Graph {
  FeatureMatrix mesh_nodes;    // one row per mesh node
  FeatureMatrix object_nodes;  // one row per object (empty without object nodes)
  EdgeSet mesh_edges;          // mesh node -> mesh node, both directions of every mesh edge
  EdgeSet object_to_mesh;      // object node -> each of its mesh nodes
  EdgeSet mesh_to_object;      // mesh node -> its object node
  EdgeSet world_edges;         // mesh node -> mesh node of another object (NoFaceCollision)
  FaceEdgeSet face_edges;      // face -> face of another object, both directions

  std::vector<std::int32_t> node_object;        // object of each mesh node
  std::vector<std::uint8_t> node_kinematic;     // 1 for nodes of kinematic objects
  std::vector<std::int32_t> object_first_node;  // objects + 1 offsets into the mesh nodes
  std::vector<std::uint8_t> object_kinematic;
  std::vector<std::int32_t> scene_first_object;  // scenes + 1 offsets into the objects

  int num_mesh_nodes() const { return static_cast<int>(node_object.size()); }
  int num_objects() const { return static_cast<int>(object_kinematic.size()); }
  int num_scenes() const { return static_cast<int>(scene_first_object.size()) - 1; }
};

// Appends the scenes of `part` to `whole`, offsetting every index: building scenes A then B into
// one graph equals building A, building B, and appending B's graph (so batches can be built by
// several threads). Throws ConfigError when their feature widths differ.
void append_graph(const Graph& part, Graph& whole);

// Splits `whole` into parts of consecutive scenes, the inverse of append_graph: part i holds
// scenes [bounds[i], bounds[i + 1]) with indices relative to it, edges in the whole's order.
// Throws ConfigError when the bounds are not increasing within [0, whole.num_scenes()], or an
// edge joins two parts.
void split_scenes(const Graph& whole, std::span<const int> bounds, std::vector<Graph>& parts);

}  // namespace fignet
