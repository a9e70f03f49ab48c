// The whole FIGNet, forward and backward, against finite differences on a tiny scene, and the
// permutation equivariance of its output.
#include <gtest/gtest.h>

#include <random>

#include "../graph/scene_fixtures.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/model/network.h"
#include "gradient_check.h"

namespace fignet {
namespace {

ModelConfig tiny_config(CollisionEdges collisions, bool object_nodes, int hidden = 0,
                        int object_hidden = 0) {
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = 8;
  config.hidden_size = hidden;
  config.object_hidden_size = object_hidden;
  config.message_passing_steps = 2;
  config.graph.collisions = collisions;
  config.graph.object_nodes = object_nodes;
  config.graph.collision_radius = 0.5;
  if (collisions == CollisionEdges::kNodeNode) config.graph.floor = FloorModel::kImplicit;
  return config;
}

struct Variant {
  CollisionEdges collisions;
  bool object_nodes;
  int hidden = 0, object_hidden = 0;  // 0: the latent width
};

class NetworkGradient : public ::testing::TestWithParam<Variant> {};

TEST_P(NetworkGradient, MatchesFiniteDifferences) {
  const ModelConfig config = tiny_config(GetParam().collisions, GetParam().object_nodes,
                                         GetParam().hidden, GetParam().object_hidden);
  const Network network(config);
  std::vector<float> params;
  network.layout().initialize(params, 7);
  // Check at a generic point: with zero biases and near-constant inputs, LayerNorm sees rows of
  // tiny variance where it is so curved that no float32 finite-difference step is accurate.
  {
    std::mt19937 noise_rng(11);
    std::normal_distribution<float> noise(0.0f, 0.3f);
    for (float& p : params) p += noise(noise_rng);
  }
  // Two tetrahedra within the collision radius of each other and of the floor: few outputs keep
  // float32 forward noise well below the derivatives being checked.
  Points v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  v.array() -= 0.25;
  Triangles f(4, 3);
  f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  const TriangleMesh tetrahedron("tetrahedron", v, f);
  Scene scene;
  const Vec3 offsets[] = {Vec3(0, 0, 0.6), Vec3(0.3, 0.2, -0.5)};
  for (int o = 0; o < 2; ++o) {
    SceneObject object;
    object.mesh = &tetrahedron;
    std::vector<Pose> poses(3);
    for (int k = 0; k < 3; ++k) {
      poses[k].position = offsets[o] + 0.01 * k * Vec3(1 + o, -o, 2);
      poses[k].orientation = Eigen::AngleAxisd(0.1 * k + o, Vec3(1, 2, 3).normalized());
    }
    set_pose_history(object, poses);
    object.properties = {1.0 + o, 0.5, 0.3};
    scene.objects.push_back(object);
  }
  scene.floor = Floor{-0.9};
  Graph graph;
  GraphBuilder(config.graph).build(scene, graph);
  if (config.graph.collisions == CollisionEdges::kFaceFace) {
    ASSERT_GT(graph.face_edges.size(), 0);
  } else {
    ASSERT_GT(graph.world_edges.size(), 0);
  }
  Normalizers normalizers = network.make_normalizers();
  network.accumulate_input_statistics(graph, normalizers);
  std::mt19937 rng(3);
  std::normal_distribution<float> n;
  RowMatrixXf weights(graph.num_mesh_nodes(), 3);
  for (int i = 0; i < weights.size(); ++i) weights.data()[i] = n(rng);

  NetworkWorkspace workspace;
  auto loss = [&](const std::vector<float>& p) {
    const ConstMatrixView out = network.forward(p.data(), normalizers, graph, workspace, false);
    return out.cast<double>().cwiseProduct(weights.cast<double>()).sum();
  };
  network.forward(params.data(), normalizers, graph, workspace, true);
  std::vector<float> grads(params.size(), 0.0f);
  network.backward(params.data(), grads.data(), graph, weights, workspace);
  EXPECT_EQ(testing::check_gradients(network.layout(), params, grads, loss, 24), 0);
}

INSTANTIATE_TEST_SUITE_P(Variants, NetworkGradient,
                         ::testing::Values(Variant{CollisionEdges::kFaceFace, true},
                                           Variant{CollisionEdges::kFaceFace, false},
                                           Variant{CollisionEdges::kNodeNode, true},
                                           Variant{CollisionEdges::kFaceFace, true, 12, 20}));

TEST(Network, ParameterNamesAreStableAndComplete) {
  const Network network(ModelConfig::preset_named("paper"));
  std::vector<std::string> names;
  for (const auto& t : network.layout().tensors()) names.push_back(t.name);
  EXPECT_EQ(names.front(), "encoder/mesh_node/linear_0/w");
  EXPECT_EQ(names.back(), "decoder/mesh_node/linear_2/b");
  EXPECT_NE(std::find(names.begin(), names.end(), "processor/9/face_edge/layer_norm/scale"),
            names.end());
  // The face-face update reads nine latents and writes three.
  for (const auto& t : network.layout().tensors()) {
    if (t.name == "processor/0/face_edge/linear_0/w") {
      EXPECT_EQ(t.rows, 9 * 128);
    }
    if (t.name == "processor/0/face_edge/linear_2/w") {
      EXPECT_EQ(t.cols, 3 * 128);
    }
  }
}

}  // namespace
}  // namespace fignet
