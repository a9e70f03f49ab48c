#include "fignet/graph/graph.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "fignet/error.h"

namespace fignet {

namespace {

// to += rows [begin, end) of from (of as many columns).
void append_row_range(const FeatureMatrix& from, int begin, int end, FeatureMatrix& to) {
  if (end <= begin) return;
  std::memcpy(to.append_rows(end - begin), from.row(begin),
              sizeof(float) * static_cast<size_t>(end - begin) * from.cols());
}

void append_rows(const FeatureMatrix& part, FeatureMatrix& whole, const char* what) {
  if (part.cols() != whole.cols()) {
    throw ConfigError(fmt::format("append_graph: {} have {} columns in the part, {} in the whole",
                                  what, part.cols(), whole.cols()));
  }
  append_row_range(part, 0, part.rows(), whole);
}

// whole += part[skip..] + offset.
void append_offset(std::span<const std::int32_t> part, std::int32_t offset,
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

// part = rows [begin, end) of whole.
void copy_rows(const FeatureMatrix& whole, int begin, int end, FeatureMatrix& part) {
  part.reset(whole.cols());
  append_row_range(whole, begin, end, part);
}

// part = whole[begin..end) - offset.
void copy_offset(const std::vector<std::int32_t>& whole, size_t begin, size_t end,
                 std::int32_t offset, std::vector<std::int32_t>& part) {
  part.clear();
  append_offset(std::span(whole).subspan(begin, end - begin), -offset, part);
}

// Where each part's nodes (or objects) start: starts[i] for part i, then the total.
struct PartStarts {
  std::vector<std::int32_t> starts;
  // The part holding index i.
  int part_of(std::int32_t i) const {
    return static_cast<int>(std::upper_bound(starts.begin(), starts.end(), i) - starts.begin()) - 1;
  }
};

// Deals each edge (`arity` senders and receivers) to the part of its first receiver, indices
// shifted to the part's; every sender and receiver must lie in that part.
template <class Edges>
void split_edges(const Edges& whole, int arity, const PartStarts& senders,
                 const PartStarts& receivers, std::vector<Graph>& parts, Edges Graph::*member,
                 const char* what) {
  for (Graph& part : parts) (part.*member).reset(whole.features.cols());
  const size_t edges = whole.receivers.size() / arity;
  for (size_t e = 0; e < edges; ++e) {
    const int p = receivers.part_of(whole.receivers[e * arity]);
    Edges& to = parts[p].*member;
    for (int j = 0; j < arity; ++j) {
      const std::int32_t s = whole.senders[e * arity + j], r = whole.receivers[e * arity + j];
      if (senders.part_of(s) != p || receivers.part_of(r) != p) {
        throw ConfigError(fmt::format("split_scenes: {} {} joins two parts", what, e));
      }
      to.senders.push_back(s - senders.starts[p]);
      to.receivers.push_back(r - receivers.starts[p]);
    }
    append_row_range(whole.features, static_cast<int>(e), static_cast<int>(e) + 1, to.features);
  }
}

}  // namespace

void split_scenes(const Graph& whole, std::span<const int> bounds, std::vector<Graph>& parts) {
  const int scenes = whole.num_scenes();
  bool valid = bounds.size() >= 2 && bounds.front() == 0 && bounds.back() == scenes;
  for (size_t i = 1; valid && i < bounds.size(); ++i) valid = bounds[i] > bounds[i - 1];
  if (!valid) {
    throw ConfigError(
        fmt::format("split_scenes: bounds must increase from 0 to the graph's {} scenes", scenes));
  }
  const int count = static_cast<int>(bounds.size()) - 1;
  parts.resize(count);
  PartStarts objects, nodes;
  for (int b : bounds) {
    objects.starts.push_back(whole.scene_first_object[b]);
    nodes.starts.push_back(whole.object_first_node[objects.starts.back()]);
  }
  for (int p = 0; p < count; ++p) {
    Graph& part = parts[p];
    const std::int32_t o0 = objects.starts[p], o1 = objects.starts[p + 1];
    const std::int32_t n0 = nodes.starts[p], n1 = nodes.starts[p + 1];
    copy_rows(whole.mesh_nodes, n0, n1, part.mesh_nodes);
    if (whole.object_nodes.rows() > 0) {
      copy_rows(whole.object_nodes, o0, o1, part.object_nodes);
    } else {
      part.object_nodes.reset(whole.object_nodes.cols());
    }
    copy_offset(whole.node_object, n0, n1, o0, part.node_object);
    part.node_kinematic.assign(whole.node_kinematic.begin() + n0,
                               whole.node_kinematic.begin() + n1);
    copy_offset(whole.object_first_node, o0, o1 + 1, n0, part.object_first_node);
    part.object_kinematic.assign(whole.object_kinematic.begin() + o0,
                                 whole.object_kinematic.begin() + o1);
    copy_offset(whole.scene_first_object, bounds[p], bounds[p + 1] + 1, o0,
                part.scene_first_object);
  }
  split_edges(whole.mesh_edges, 1, nodes, nodes, parts, &Graph::mesh_edges, "mesh edge");
  split_edges(whole.object_to_mesh, 1, objects, nodes, parts, &Graph::object_to_mesh,
              "object-mesh edge");
  split_edges(whole.mesh_to_object, 1, nodes, objects, parts, &Graph::mesh_to_object,
              "mesh-object edge");
  split_edges(whole.world_edges, 1, nodes, nodes, parts, &Graph::world_edges, "world edge");
  split_edges(whole.face_edges, 3, nodes, nodes, parts, &Graph::face_edges, "face edge");
}

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
