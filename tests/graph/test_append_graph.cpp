// append_graph: a batch built in parts and appended equals the batch built at once, field by field.
#include <gtest/gtest.h>

#include "fignet/error.h"
#include "fignet/graph/graph_builder.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

void expect_same_edges(const EdgeSet& a, const EdgeSet& b) {
  EXPECT_EQ(a.senders, b.senders);
  EXPECT_EQ(a.receivers, b.receivers);
  EXPECT_EQ(a.features.matrix(), b.features.matrix());
}

class AppendGraph : public ::testing::TestWithParam<CollisionEdges> {};

TEST_P(AppendGraph, PartsAppendedEqualTheWholeBatch) {
  GraphConfig config;
  config.collisions = GetParam();
  config.collision_radius = 0.3;
  std::vector<testing::RandomScene> owned;
  std::vector<Scene> scenes;
  for (unsigned s = 0; s < 5; ++s) owned.push_back(testing::make_random_scene(s + 1, 3 + s, 0.4));
  for (const auto& r : owned) scenes.push_back(r.scene);

  GraphBuilder builder(config);
  Graph whole, parts, tail;
  builder.build(scenes, whole);
  ASSERT_GT(config.collisions == CollisionEdges::kFaceFace ? whole.face_edges.size()
                                                           : whole.world_edges.size(),
            0);
  // Scenes 0–1 into one graph, 2–4 into another, then appended.
  builder.build(std::span(scenes).first(2), parts);
  builder.build(std::span(scenes).subspan(2), tail);
  append_graph(tail, parts);

  EXPECT_EQ(parts.mesh_nodes.matrix(), whole.mesh_nodes.matrix());
  EXPECT_EQ(parts.object_nodes.matrix(), whole.object_nodes.matrix());
  expect_same_edges(parts.mesh_edges, whole.mesh_edges);
  expect_same_edges(parts.object_to_mesh, whole.object_to_mesh);
  expect_same_edges(parts.mesh_to_object, whole.mesh_to_object);
  expect_same_edges(parts.world_edges, whole.world_edges);
  EXPECT_EQ(parts.face_edges.senders, whole.face_edges.senders);
  EXPECT_EQ(parts.face_edges.receivers, whole.face_edges.receivers);
  EXPECT_EQ(parts.face_edges.features.matrix(), whole.face_edges.features.matrix());
  EXPECT_EQ(parts.node_object, whole.node_object);
  EXPECT_EQ(parts.node_kinematic, whole.node_kinematic);
  EXPECT_EQ(parts.object_first_node, whole.object_first_node);
  EXPECT_EQ(parts.object_kinematic, whole.object_kinematic);
  EXPECT_EQ(parts.scene_first_object, whole.scene_first_object);
}

INSTANTIATE_TEST_SUITE_P(Collisions, AppendGraph,
                         ::testing::Values(CollisionEdges::kFaceFace, CollisionEdges::kNodeNode));

TEST(AppendGraph, RejectsGraphsOfOtherFeatureWidths) {
  GraphConfig face, node;
  node.collisions = CollisionEdges::kNodeNode;
  node.floor = FloorModel::kImplicit;
  const auto scene = testing::make_random_scene(1, 2, 0.4);
  Graph a, b;
  GraphBuilder(face).build(scene.scene, a);
  GraphBuilder(node).build(scene.scene, b);
  EXPECT_THROW(append_graph(b, a), ConfigError);
}

}  // namespace
}  // namespace fignet
