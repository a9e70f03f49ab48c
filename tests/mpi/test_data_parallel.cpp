// Data-parallel training under `mpirun -np 2`: the processes stay bit-identical, and two
// processes with B samples each train like one process with the 2B samples.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>

#include "../model/trajectory_fixtures.h"
#include "fignet/parallel/mpi_collective.h"
#include "fignet/train/trainer.h"

namespace fignet {
namespace {

// Four trajectories of falling, spinning cubes, different in each.
std::vector<Trajectory> all_trajectories() {
  const double dt = 1.0 / 48.0;
  std::vector<Trajectory> data;
  for (int i = 0; i < 4; ++i) {
    Trajectory t;
    t.time_step = dt;
    t.objects.push_back(testing::ballistic_object(testing::small_cube(0.2 + 0.05 * i),
                                                  Vec3(0, 0, 2 + i), Vec3(1, -i, 0), Vec3(i, 4, 2),
                                                  10, dt, Vec3(0, 0, -10)));
    t.objects.push_back(testing::ballistic_object(testing::small_cube(0.3), Vec3(0, 0.8, 2),
                                                  Vec3(0, 1, i), Vec3(-3, 0, 5), 10, dt,
                                                  Vec3(0, 0, -10)));
    data.push_back(t);
  }
  return data;
}

ModelConfig tiny_model(double noise) {
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = 16;
  config.message_passing_steps = 2;
  config.noise_std = noise;
  return config;
}

std::vector<Trajectory> share(const std::vector<Trajectory>& all, int rank, int size) {
  std::vector<Trajectory> mine;
  for (size_t i = static_cast<size_t>(rank); i < all.size(); i += static_cast<size_t>(size)) {
    mine.push_back(all[i]);
  }
  return mine;
}

TEST(DataParallel, ProcessesStayBitIdenticalAfterEveryStep) {
  MpiCollective processes;
  ASSERT_EQ(processes.size(), 2) << "run under mpirun -np 2";
  const auto all = all_trajectories();
  const auto mine = share(all, processes.rank(), processes.size());
  TrainerConfig config;
  config.batch_size = 4;
  Trainer trainer(tiny_model(1e-3), config, mine, nullptr, &processes);
  for (int step = 0; step < 5; ++step) {
    trainer.step();
    // Process 0's parameters everywhere, compared bit for bit.
    std::vector<float> root(trainer.parameters());
    MPI_Bcast(root.data(), static_cast<int>(root.size()), MPI_FLOAT, 0, MPI_COMM_WORLD);
    ASSERT_TRUE(std::equal(root.begin(), root.end(), trainer.parameters().begin()))
        << "process " << processes.rank() << " differs after step " << step + 1;
  }
}

// Process r trains on its samples S_r (B each); one process trains on S_0 ∪ S_1 (2B). Without
// noise the two see the same graphs, so only the order of floating-point sums differs: the
// gradient is summed over processes in float and the statistics in double, instead of in one
// pass. That changes the loss by float rounding (relative 1e-6) and each gradient entry by a
// relative 1e-7; Adam's step is m/√v, so the parameters move apart by about that fraction of the
// learning rate (1e-3) per step: 3e-8 was measured after 3 steps. 1e-6 allows for a gradient
// entry near zero, whose relative rounding is larger, and is still 1000× below one step's
// update, which any real difference (a lost sample, a wrong scale) would show.
TEST(DataParallel, TwoProcessesWithBEqualOneWith2B) {
  MpiCollective processes;
  const auto all = all_trajectories();
  const int rank = processes.rank();
  const auto mine = share(all, rank, 2);
  TrainerConfig config;
  config.batch_size = 4;  // global: 2 per process
  Trainer parallel(tiny_model(0.0), config, mine, nullptr, &processes);
  Trainer single(tiny_model(0.0), config, all);  // every process runs the reference alone
  for (int step = 0; step < 3; ++step) {
    // Samples by local index on each process; the same samples by global index for the reference.
    const std::vector<SampleRef> local = {{0, 2 + step}, {1, 5 - step}};
    std::vector<SampleRef> global;
    for (int r = 0; r < 2; ++r) {
      for (const SampleRef& s : local) global.push_back({s.trajectory * 2 + r, s.frame});
    }
    const TrainStep a = parallel.step_on(local, 0);
    const TrainStep b = single.step_on(global, 0);
    EXPECT_NEAR(a.loss, b.loss, 1e-6 * b.loss) << "step " << step + 1;
  }
  float largest = 0.0f;
  for (size_t i = 0; i < single.parameters().size(); ++i) {
    largest = std::max(largest, std::abs(parallel.parameters()[i] - single.parameters()[i]));
  }
  EXPECT_LT(largest, 1e-6f);
  const auto& p = parallel.normalizers().target;
  const auto& s = single.normalizers().target;
  EXPECT_EQ(p.count(), s.count());
  EXPECT_TRUE(p.mean().isApprox(s.mean(), 1e-6f));
  EXPECT_TRUE(p.std().isApprox(s.std(), 1e-6f));
}

}  // namespace
}  // namespace fignet

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  fignet::MpiSession mpi(&argc, &argv);
  if (!mpi.active()) {
    std::fprintf(stderr, "test_data_parallel: start it with mpirun -np 2\n");
    return 77;
  }
  // Only process 0 reports; every process runs every test.
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  const int failed = RUN_ALL_TESTS();
  int any = failed;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any;
}
