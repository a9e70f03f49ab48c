// Scene::num_nodes: the rows of a scene's per-node arrays, which the graph builder lays out
// object by object before a mesh floor's nodes.
#include <gtest/gtest.h>

#include "fignet/graph/graph_builder.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

TEST(Scene, NodesAreTheObjectsVerticesWithoutTheFloors) {
  const testing::RandomScene random = testing::make_random_scene(7, 5, 0.4);
  const Scene& scene = random.scene;
  GraphConfig config;
  config.floor = FloorModel::kMesh;
  Graph graph;
  GraphBuilder(config).build(scene, graph);

  // The floor is an object of the graph, its nodes after the scene's objects'.
  ASSERT_EQ(graph.object_first_node.size(), scene.objects.size() + 2);
  EXPECT_EQ(scene.num_nodes(), graph.object_first_node[scene.objects.size()]);
  EXPECT_LT(scene.num_nodes(), graph.num_mesh_nodes());
  // A sum over meshes of different sizes, not a count of objects times one mesh.
  EXPECT_NE(random.meshes[0]->num_vertices(), random.meshes[1]->num_vertices());
  EXPECT_EQ(Scene{}.num_nodes(), 0);
}

}  // namespace
}  // namespace fignet
