// Internal: the feature rows of each node and edge type (seed C.1.1 with C.2's norm features).
#pragma once

#include "fignet/graph/config.h"
#include "fignet/graph/contacts.h"
#include "fignet/graph/graph.h"
#include "fignet/graph/scene.h"

namespace fignet::detail {

// Appends the mesh-node rows of `object` (floor = nullptr when there is no implicit floor).
void append_mesh_nodes(const GraphConfig& config, const SceneObject& object, const Floor* floor,
                       FeatureMatrix& out);
void append_object_node(const GraphConfig& config, const SceneObject& object, FeatureMatrix& out);
// Both directions of every mesh edge of `object`, whose first node has global index `first`.
void append_mesh_edges(const SceneObject& object, int first, EdgeSet& out);
// Object->mesh and mesh->object edges between object node `object_index` and its nodes.
void append_object_mesh_edges(const SceneObject& object, int object_index, int first,
                              EdgeSet& object_to_mesh, EdgeSet& mesh_to_object);
// Both directions of a face pair; first_a/first_b are the objects' first global node indices.
// config's face_span_limit and distance_log_scale shape the rows.
void append_face_edges(const GraphConfig& config, const FacePair& pair, const PosedMesh& a,
                       const PosedMesh& b, int first_a, int first_b, FaceEdgeSet& out);
void append_world_edges(const NodePair& pair, const PosedMesh& a, const PosedMesh& b, int first_a,
                        int first_b, EdgeSet& out);

}  // namespace fignet::detail
