// The CUDA backend against the CPU path (the reference): forward outputs and gradients on random
// multi-object scenes for every graph variant, bitwise repeatability, and training steps that
// track each other. Every test is skipped where no GPU is visible.
#include <gtest/gtest.h>

#include <random>

#include "../graph/scene_fixtures.h"
#include "fignet/cuda/cuda_backend.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/train/trainer.h"

namespace fignet {
namespace {

#define SKIP_WITHOUT_GPU() \
  if (cuda::device_count() == 0) GTEST_SKIP() << "skipped: no GPU"

struct Variant {
  const char* name;
  CollisionEdges collisions;
  bool object_nodes;
  int latent_size, steps;
  int hidden_size = 0, object_hidden_size = 0;  // 0: the latent width
};

ModelConfig config_of(const Variant& v) {
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = v.latent_size;
  config.message_passing_steps = v.steps;
  config.hidden_size = v.hidden_size;
  config.object_hidden_size = v.object_hidden_size;
  config.graph.collisions = v.collisions;
  config.graph.object_nodes = v.object_nodes;
  config.graph.collision_radius = 0.3;
  if (v.collisions == CollisionEdges::kNodeNode) config.graph.floor = FloorModel::kImplicit;
  return config;
}

// ‖a − b‖ / ‖b‖ over all entries.
double relative_difference(const float* a, const float* b, size_t n) {
  double diff = 0.0, norm = 0.0;
  for (size_t i = 0; i < n; ++i) {
    diff += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    norm += double(b[i]) * b[i];
  }
  return std::sqrt(diff / std::max(norm, 1e-300));
}

class CudaAgainstCpu : public ::testing::TestWithParam<Variant> {};

TEST_P(CudaAgainstCpu, ForwardAndGradientsAgree) {
  SKIP_WITHOUT_GPU();
  const ModelConfig config = config_of(GetParam());
  const Network network(config);
  std::vector<float> params;
  network.layout().initialize(params, 5);
  {  // away from the initial zero biases and unit scales
    std::mt19937 rng(9);
    std::normal_distribution<float> noise(0.0f, 0.05f);
    for (float& p : params) p += noise(rng);
  }
  std::vector<testing::RandomScene> owned;
  std::vector<Scene> scenes;
  for (unsigned s = 0; s < 4; ++s) owned.push_back(testing::make_random_scene(s + 3, 4 + s, 0.4));
  for (const auto& r : owned) scenes.push_back(r.scene);
  Graph graph;
  GraphBuilder(config.graph).build(scenes, graph);
  ASSERT_GT(graph.face_edges.size() + graph.world_edges.size(), 0);
  Normalizers normalizers = network.make_normalizers();
  network.accumulate_input_statistics(graph, normalizers);
  RowMatrixXf d_output(graph.num_mesh_nodes(), 3);
  std::mt19937 rng(4);
  std::normal_distribution<float> n;
  for (Eigen::Index i = 0; i < d_output.size(); ++i) d_output.data()[i] = n(rng);

  auto cpu = make_cpu_backend(network);
  auto gpu = cuda::make_cuda_backend(network);
  const RowMatrixXf cpu_out = cpu->forward(params.data(), normalizers, graph, true);
  std::vector<float> cpu_grads(params.size(), 0.0f), gpu_grads(params.size(), 0.0f);
  cpu->backward(params.data(), cpu_grads.data(), graph, d_output);
  // Poisoned outputs: every entry must be written.
  const RowMatrixXf gpu_out = gpu->forward(params.data(), normalizers, graph, true);
  ASSERT_EQ(gpu_out.rows(), cpu_out.rows());
  ASSERT_TRUE(gpu_out.allFinite());
  gpu->backward(params.data(), gpu_grads.data(), graph, d_output);

  EXPECT_LT(relative_difference(gpu_out.data(), cpu_out.data(), cpu_out.size()), 1e-4);
  EXPECT_LT(relative_difference(gpu_grads.data(), cpu_grads.data(), params.size()), 1e-4);
  // Tensor by tensor, so a missed block shows by name.
  for (const TensorInfo& t : network.layout().tensors()) {
    EXPECT_LT(
        relative_difference(gpu_grads.data() + t.offset, cpu_grads.data() + t.offset, t.size()),
        1e-3)
        << t.name;
  }
  // Inference (two levels kept) gives the training forward's output.
  const RowMatrixXf inference = gpu->forward(params.data(), normalizers, graph, false);
  EXPECT_EQ(inference, gpu_out);
  // Repeatable to the bit: segment sums are ordered, not atomic.
  std::vector<float> again(params.size(), 0.0f);
  gpu->forward(params.data(), normalizers, graph, true);
  gpu->backward(params.data(), again.data(), graph, d_output);
  EXPECT_EQ(again, gpu_grads);
}

INSTANTIATE_TEST_SUITE_P(
    Variants, CudaAgainstCpu,
    ::testing::Values(Variant{"face_object", CollisionEdges::kFaceFace, true, 16, 2},
                      Variant{"face_no_object", CollisionEdges::kFaceFace, false, 16, 2},
                      Variant{"node_node", CollisionEdges::kNodeNode, true, 16, 2},
                      Variant{"small_preset", CollisionEdges::kFaceFace, true, 64, 5},
                      Variant{"wider_hidden", CollisionEdges::kFaceFace, true, 16, 2, 24, 40}),
    [](const auto& info) { return std::string(info.param.name); });

// Trajectories of a few random scenes moving at constant velocity.
std::vector<Trajectory> drifting_scenes(std::vector<std::shared_ptr<const TriangleMesh>>& meshes) {
  std::vector<Trajectory> data;
  for (unsigned s = 0; s < 3; ++s) {
    Trajectory t;
    t.time_step = 1.0 / 48.0;
    t.floor = Floor{};
    auto scene = testing::make_random_scene(s + 10, 3, 0.5);
    for (size_t o = 0; o < scene.scene.objects.size(); ++o) {
      TrajectoryObject object;
      object.mesh = scene.meshes[o];
      meshes.push_back(scene.meshes[o]);
      object.properties = {1.0 + o, 0.5, 0.3};
      for (int f = 0; f < 8; ++f) {
        Pose pose;
        pose.position = Vec3(0.3 * o, 0.1 * s, 0.5 + 0.02 * f);
        pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * f * (o + 1), Vec3::UnitZ()));
        object.poses.push_back(pose);
      }
      t.objects.push_back(std::move(object));
    }
    data.push_back(std::move(t));
  }
  return data;
}

TEST(CudaTraining, StepsTrackTheCpuTrainer) {
  SKIP_WITHOUT_GPU();
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;
  const std::vector<Trajectory> data = drifting_scenes(meshes);
  ModelConfig config = config_of({"", CollisionEdges::kFaceFace, true, 16, 2});
  TrainerConfig trainer_config;
  trainer_config.batch_size = 3;
  Trainer cpu(config, trainer_config, data), gpu(config, trainer_config, data);
  gpu.set_backend(cuda::make_cuda_backend(gpu.network()));
  for (int i = 0; i < 5; ++i) {
    const TrainStep a = cpu.step(), b = gpu.step();
    EXPECT_NEAR(b.loss, a.loss, 1e-3 * std::max(1.0, a.loss)) << "step " << i;
  }
  EXPECT_LT(relative_difference(gpu.parameters().data(), cpu.parameters().data(),
                                cpu.parameters().size()),
            1e-4);
}

TEST(CudaBackend, BadDeviceIndexIsAnError) {
  SKIP_WITHOUT_GPU();
  const Network network(config_of({"", CollisionEdges::kFaceFace, true, 8, 1}));
  EXPECT_THROW(cuda::make_cuda_backend(network, {cuda::device_count(), false}), cuda::DeviceError);
}

}  // namespace
}  // namespace fignet
