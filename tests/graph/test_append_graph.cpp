// append_graph: a batch built in parts and appended equals the batch built at once, field by field;
// extract_scenes, its inverse, gives back the parts.
#include <gtest/gtest.h>

#include "../error_text.h"
#include "fignet/error.h"
#include "fignet/graph/graph_builder.h"
#include "graph_compare.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

using testing::expect_same_graph;

class AppendGraph : public ::testing::TestWithParam<CollisionEdges> {
 protected:
  // `count` random scenes of first_objects, first_objects + 1, ... objects.
  void make_scenes(int count, unsigned first_seed, int first_objects) {
    config.collisions = GetParam();
    config.collision_radius = 0.3;
    for (int s = 0; s < count; ++s) {
      owned.push_back(testing::make_random_scene(first_seed + s, first_objects + s, 0.4));
    }
    for (const auto& r : owned) scenes.push_back(r.scene);
  }

  GraphConfig config;
  std::vector<testing::RandomScene> owned;
  std::vector<Scene> scenes;
};

TEST_P(AppendGraph, PartsAppendedEqualTheWholeBatch) {
  make_scenes(5, 1, 3);
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

  expect_same_graph(parts, whole);
}

// Split at any bounds, each part equals its scenes built alone.
TEST_P(AppendGraph, SplitPartsEqualTheirScenesBuiltAlone) {
  make_scenes(4, 7, 2);
  GraphBuilder builder(config);
  Graph whole, alone;
  builder.build(scenes, whole);
  std::vector<Graph> parts;
  for (const std::vector<int>& bounds :
       {std::vector<int>{0, 4}, {0, 1, 2, 3, 4}, {0, 3, 4}, {0, 1, 4}, {0, 2, 3, 4}}) {
    split_scenes(whole, bounds, parts);
    ASSERT_EQ(parts.size(), bounds.size() - 1);
    for (size_t p = 0; p + 1 < bounds.size(); ++p) {
      SCOPED_TRACE(::testing::Message() << "scenes [" << bounds[p] << ", " << bounds[p + 1] << ")");
      builder.build(std::span(scenes).subspan(bounds[p], bounds[p + 1] - bounds[p]), alone);
      expect_same_graph(parts[p], alone);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Collisions, AppendGraph,
                         ::testing::Values(CollisionEdges::kFaceFace, CollisionEdges::kNodeNode));

TEST(SplitScenes, RejectsBadBoundsAndEdgesBetweenParts) {
  std::vector<testing::RandomScene> owned;
  std::vector<Scene> scenes;
  for (unsigned s = 0; s < 3; ++s) owned.push_back(testing::make_random_scene(s + 1, 3, 0.4));
  for (const auto& r : owned) scenes.push_back(r.scene);
  Graph whole;
  GraphBuilder(GraphConfig{}).build(scenes, whole);
  std::vector<Graph> parts;
  for (const std::vector<int>& bounds :
       {std::vector<int>{0, 4}, {1, 3}, {0, 2, 2, 3}, {0}, {0, 2, 1, 3}}) {
    EXPECT_THROW(split_scenes(whole, bounds, parts), ConfigError);
  }
  // An edge from scene 0 to scene 2 cannot be dealt to one part.
  whole.mesh_edges.senders.front() = whole.num_mesh_nodes() - 1;
  EXPECT_EQ(testing::error_of([&] {
              split_scenes(whole, std::vector<int>{0, 1, 3}, parts);
            }),
            "split_scenes: mesh edge 0 joins two parts");
}

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
