// Field-by-field equality of two graphs, for tests that build one graph two ways.
#pragma once

#include <gtest/gtest.h>

#include "fignet/graph/graph.h"

namespace fignet::testing {

inline void expect_same_edges(const EdgeSet& a, const EdgeSet& b) {
  EXPECT_EQ(a.senders, b.senders);
  EXPECT_EQ(a.receivers, b.receivers);
  EXPECT_EQ(a.features.matrix(), b.features.matrix());
}

inline void expect_same_graph(const Graph& a, const Graph& b) {
  EXPECT_EQ(a.mesh_nodes.matrix(), b.mesh_nodes.matrix());
  EXPECT_EQ(a.object_nodes.matrix(), b.object_nodes.matrix());
  expect_same_edges(a.mesh_edges, b.mesh_edges);
  expect_same_edges(a.object_to_mesh, b.object_to_mesh);
  expect_same_edges(a.mesh_to_object, b.mesh_to_object);
  expect_same_edges(a.world_edges, b.world_edges);
  EXPECT_EQ(a.face_edges.senders, b.face_edges.senders);
  EXPECT_EQ(a.face_edges.receivers, b.face_edges.receivers);
  EXPECT_EQ(a.face_edges.features.matrix(), b.face_edges.features.matrix());
  EXPECT_EQ(a.node_object, b.node_object);
  EXPECT_EQ(a.node_kinematic, b.node_kinematic);
  EXPECT_EQ(a.object_first_node, b.object_first_node);
  EXPECT_EQ(a.object_kinematic, b.object_kinematic);
  EXPECT_EQ(a.scene_first_object, b.scene_first_object);
}

}  // namespace fignet::testing
