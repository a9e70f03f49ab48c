#include "fignet/graph/graph.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "fignet/error.h"

namespace fignet {

namespace {

void append_rows(const FeatureMatrix& part, FeatureMatrix& whole, const char* what) {
  if (part.cols() != whole.cols()) {
    throw ConfigError(fmt::format("append_graph: {} have {} columns in the part, {} in the whole",
                                  what, part.cols(), whole.cols()));
  }
  if (part.rows() == 0) return;
  float* to = whole.append_rows(part.rows());
  std::memcpy(to, part.row(0), sizeof(float) * part.rows() * part.cols());
}

// whole += part[skip..] + offset.
void append_offset(const std::vector<std::int32_t>& part, std::int32_t offset,
                   std::vector<std::int32_t>& whole, size_t skip = 0) {
  if (part.size() <= skip) return;
  const size_t start = whole.size();
  whole.resize(start + part.size() - skip);
  std::transform(part.begin() + skip, part.end(), whole.begin() + start,
                 [offset](std::int32_t i) { return i + offset; });
}

void append_edges(const EdgeSet& part, std::int32_t sender_offset, std::int32_t receiver_offset,
                  EdgeSet& whole, const char* what) {
  append_offset(part.senders, sender_offset, whole.senders);
  append_offset(part.receivers, receiver_offset, whole.receivers);
  append_rows(part.features, whole.features, what);
}

}  // namespace

void append_graph(const Graph& part, Graph& whole) {
  const std::int32_t nodes = whole.num_mesh_nodes(), objects = whole.num_objects();
  append_rows(part.mesh_nodes, whole.mesh_nodes, "mesh nodes");
  append_rows(part.object_nodes, whole.object_nodes, "object nodes");
  append_edges(part.mesh_edges, nodes, nodes, whole.mesh_edges, "mesh edges");
  append_edges(part.object_to_mesh, objects, nodes, whole.object_to_mesh, "object-mesh edges");
  append_edges(part.mesh_to_object, nodes, objects, whole.mesh_to_object, "mesh-object edges");
  append_edges(part.world_edges, nodes, nodes, whole.world_edges, "world edges");
  append_offset(part.face_edges.senders, nodes, whole.face_edges.senders);
  append_offset(part.face_edges.receivers, nodes, whole.face_edges.receivers);
  append_rows(part.face_edges.features, whole.face_edges.features, "face edges");
  append_offset(part.node_object, objects, whole.node_object);
  whole.node_kinematic.insert(whole.node_kinematic.end(), part.node_kinematic.begin(),
                              part.node_kinematic.end());
  // Offset arrays: the part's first entry (0) is the whole's last.
  append_offset(part.object_first_node, nodes, whole.object_first_node, 1);
  whole.object_kinematic.insert(whole.object_kinematic.end(), part.object_kinematic.begin(),
                                part.object_kinematic.end());
  append_offset(part.scene_first_object, objects, whole.scene_first_object, 1);
}

}  // namespace fignet
