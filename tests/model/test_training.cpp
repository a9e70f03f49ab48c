#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "../graph/scene_fixtures.h"
#include "../scoped_threads.h"
#include "fignet/error.h"
#include "fignet/rollout/predictor.h"
#include "fignet/rollout/rollout.h"
#include "fignet/train/trainer.h"
#include "model_fixtures.h"
#include "trajectory_fixtures.h"

namespace fignet {
namespace {

ModelConfig small_model() {
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = 32;
  config.message_passing_steps = 2;
  config.noise_std = 0.0;
  return config;
}

std::vector<Trajectory> spinning_cubes(int frames) {
  const double dt = 1.0 / 48.0;
  Trajectory trajectory;
  trajectory.time_step = dt;
  trajectory.objects.push_back(testing::ballistic_object(testing::small_cube(), Vec3(0, 0, 2),
                                                         Vec3(1, 0, 0), Vec3(0, 4, 2), frames, dt,
                                                         Vec3(0, 0, -10)));
  trajectory.objects.push_back(testing::ballistic_object(testing::small_cube(0.3), Vec3(0, 0.8, 2),
                                                         Vec3(0, 1, 1), Vec3(-3, 0, 5), frames, dt,
                                                         Vec3(0, 0, -10)));
  return {trajectory};
}

// small_model() with the recipe's rigid-body noise.
ModelConfig noisy_model() {
  ModelConfig config = small_model();
  config.noise_std = 1e-3;
  config.noise = NoiseKind::kRigid;
  return config;
}

TEST(Trainer, OverfitsOneShortTrajectoryByAHundredfold) {
  const auto data = spinning_cubes(12);
  TrainerConfig trainer_config;
  trainer_config.batch_size = 4;
  trainer_config.adam.decay_steps = 1500;
  Trainer trainer(small_model(), trainer_config, data);
  const std::vector<SampleRef> all = trainer.samples();
  trainer.step();  // statistics from the first batch
  const double before = trainer.evaluate_loss(all);
  trainer.run(1500, nullptr);
  const double after = trainer.evaluate_loss(all);
  EXPECT_LT(after, before / 100.0) << "before " << before << ", after " << after;
}

// Batches are built in parallel parts (one per thread) and appended; noise comes from one seed per
// scene. Neither may depend on the thread count (3 and 5 cut 16 scenes unevenly). Also covers the
// recipe's levers.
TEST(Trainer, BatchesDoNotDependOnTheThreadCount) {
  const auto data = spinning_cubes(10);
  ModelConfig config = noisy_model();
  config.graph.static_internal_edges = false;
  config.graph.log_mass = true;
  TrainerConfig trainer_config;
  trainer_config.batch_size = 16;
  trainer_config.gradient_clip = 0.5f;
  trainer_config.huber_delta = 1.0f;
  trainer_config.pushforward_fraction = 0.5f;
  auto train = [&](int threads) {
    const testing::ScopedThreads scope(threads);
    Trainer trainer(config, trainer_config, data);
    trainer.warm_up_statistics(2);
    std::vector<double> losses;
    for (int i = 0; i < 3; ++i) losses.push_back(trainer.step().loss);
    return std::pair(losses, trainer.parameters());
  };
  const auto one = train(1);
  for (int threads : {3, 5}) {
    const auto many = train(threads);
    EXPECT_EQ(one.first, many.first) << threads << " threads";
    EXPECT_EQ(one.second, many.second) << threads << " threads";
  }
}

// Building each step's batch ahead, on another thread while the step before trains, changes
// when it is built and nothing else: the same losses and parameters, also where the batch built
// ahead is no longer the next step's (after step_on and restore) and is drawn anew.
TEST(Trainer, BuildingAheadTrainsTheSameBits) {
  const auto data = spinning_cubes(10);
  TrainerConfig trainer_config;
  trainer_config.batch_size = 6;
  trainer_config.rest_loss_weight = 10.0f;
  trainer_config.weight_average = 0.9f;
  trainer_config.pushforward_fraction = 0.5f;
  auto train = [&](bool ahead) {
    const testing::ScopedThreads scope(2);
    Trainer trainer(noisy_model(), trainer_config, data);
    trainer.set_build_ahead(ahead);
    EXPECT_EQ(trainer.builds_ahead(), ahead);
    trainer.warm_up_statistics(1);
    std::vector<double> losses;
    for (int i = 0; i < 3; ++i) losses.push_back(trainer.step().loss);
    const std::vector<SampleRef> first(trainer.samples().begin(), trainer.samples().begin() + 4);
    losses.push_back(trainer.step_on(first, 7).loss);
    losses.push_back(trainer.step().loss);
    TrainerState later = trainer.state();
    later.step += 10;
    trainer.restore(later);
    for (int i = 0; i < 2; ++i) losses.push_back(trainer.step().loss);
    losses.push_back(trainer.evaluate_loss(first));
    trainer.set_build_ahead(false);
    losses.push_back(trainer.step().loss);
    EXPECT_EQ(trainer.steps_done(), 18);
    return std::tuple(losses, trainer.parameters(), trainer.model()->parameters());
  };
  const auto [plain_losses, plain_parameters, plain_average] = train(false);
  const auto [ahead_losses, ahead_parameters, ahead_average] = train(true);
  EXPECT_EQ(plain_losses, ahead_losses);
  EXPECT_EQ(plain_parameters, ahead_parameters);
  EXPECT_EQ(plain_average, ahead_average);
}

// The loss over every sample of an untrained model under `trainer_config`, after one batch of
// statistics (the parameters untouched).
double untrained_loss(const TrainerConfig& trainer_config, const std::vector<Trajectory>& data) {
  Trainer trainer(small_model(), trainer_config, data);
  trainer.warm_up_statistics(1);
  return trainer.evaluate_loss(trainer.samples());
}

// Huber's loss equals the squared error within delta and grows only linearly beyond it.
TEST(Trainer, HuberLossIsQuadraticWithinDeltaAndLinearBeyond) {
  const auto data = spinning_cubes(10);
  auto loss_with = [&](float delta) {
    TrainerConfig trainer_config;
    trainer_config.huber_delta = delta;
    return untrained_loss(trainer_config, data);
  };
  const double squared = loss_with(0.0f);
  ASSERT_GT(squared, 0.0);
  EXPECT_DOUBLE_EQ(loss_with(1e6f), squared);
  const double huber = loss_with(0.05f);
  EXPECT_LT(huber, squared);
  EXPECT_GT(huber, 0.0);
}

// A cube flying and a cube lying still: only the second is at rest in the truth.
std::vector<Trajectory> flying_and_resting_cubes(int frames) {
  auto data = spinning_cubes(frames);
  data[0].objects[1] =
      testing::ballistic_object(testing::small_cube(0.3), Vec3(0, 3, 0.3), Vec3::Zero(),
                                Vec3::Zero(), frames, 1.0 / 48.0, Vec3::Zero());
  return data;
}

// The target's next position, x̃^t + (x̃^t − x̃^{t−1}) + target, is the clean next frame plus the
// share 1 − c of the current position's noise: c = 0 undoes the velocity noise only, c = 1 the
// position noise too. Checked against the clean scene for both kinds of noise.
TEST(TrainingBatch, TargetUndoesTheVelocityNoiseAndTheChosenShareOfThePositionNoise) {
  const auto data = spinning_cubes(8);
  const int history = ModelConfig::preset_named("small").graph.history, frame = 4;
  Scene clean;
  scene_at_frame(data[0], frame, history, clean);
  for (NoiseKind kind : {NoiseKind::kVertex, NoiseKind::kRigid}) {
    for (double correction : {0.0, 0.5, 1.0}) {
      std::mt19937_64 rng(7);
      Scene noisy;
      Points targets;
      make_noisy_sample(data[0], frame, history, 1e-2, kind, correction, rng, noisy, targets);
      Eigen::Index row = 0;
      for (size_t o = 0; o < noisy.objects.size(); ++o) {
        const SceneObject& object = noisy.objects[o];
        const Eigen::Index v = object.mesh->num_vertices();
        const Points noise = object.positions_at(history) - clean.objects[o].positions_at(history);
        ASSERT_GT(noise.norm(), 1e-3);  // the noise is there to be undone
        const Points next = 2.0 * object.positions_at(history) - object.positions_at(history - 1) +
                            targets.middleRows(row, v);
        const Points clean_next = posed_vertices(*object.mesh, data[0].objects[o].poses[frame + 1]);
        EXPECT_LT((next - (clean_next + (1.0 - correction) * noise)).cwiseAbs().maxCoeff(), 1e-12)
            << "object " << o << ", correction " << correction;
        row += v;
      }
    }
  }
}

// The turn about the vertical through the floor's centre, checked point by point against
// x' = c + R(θ)(x − c) written out with cos and sin: every history step, the kinematic body's next
// pose, and the targets, whose next positions must be the turned clean next frame.
TEST(TrainingBatch, TurnAboutTheVerticalTurnsPositionsAndTargetsTogether) {
  auto data = spinning_cubes(8);
  data[0].objects[1].kinematic = true;
  data[0].floor = Floor{};
  data[0].floor->center_x = 1.0, data[0].floor->center_y = -2.0;
  const int history = ModelConfig::preset_named("small").graph.history, frame = 4;
  std::mt19937_64 rng(7);
  Scene scene;
  Points targets;
  make_noisy_sample(data[0], frame, history, 0.0, NoiseKind::kVertex, 0.0, rng, scene, targets);
  const Scene before = scene;
  const double angle = 0.7, c = std::cos(angle), s = std::sin(angle);
  auto turned = [&](const Points& p, bool about_center) {
    const double cx = about_center ? 1.0 : 0.0, cy = about_center ? -2.0 : 0.0;
    Points out = p;
    out.col(0) = (c * (p.col(0).array() - cx) - s * (p.col(1).array() - cy) + cx).matrix();
    out.col(1) = (s * (p.col(0).array() - cx) + c * (p.col(1).array() - cy) + cy).matrix();
    return out;
  };
  Points turned_targets = targets;
  turn_about_vertical(angle, scene, turned_targets);
  EXPECT_LT((turned_targets - turned(targets, false)).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::Index row = 0;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const SceneObject &now = scene.objects[o], &was = before.objects[o];
    EXPECT_LT((now.positions - turned(was.positions, true)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((now.centers - turned(was.centers, true)).cwiseAbs().maxCoeff(), 1e-12);
    const Eigen::Index v = now.mesh->num_vertices();
    if (now.kinematic) {
      EXPECT_LT((now.next_positions - turned(was.next_positions, true)).cwiseAbs().maxCoeff(),
                1e-12);
      EXPECT_LT((now.next_center.transpose() - turned(was.next_center.transpose(), true))
                    .cwiseAbs()
                    .maxCoeff(),
                1e-12);
    } else {
      const Points next = 2.0 * now.positions_at(history) - now.positions_at(history - 1) +
                          turned_targets.middleRows(row, v);
      const Points clean_next = posed_vertices(*now.mesh, data[0].objects[o].poses[frame + 1]);
      EXPECT_LT((next - turned(clean_next, true)).cwiseAbs().maxCoeff(), 1e-12) << "object " << o;
    }
    row += v;
  }
}

// random_yaw turns the samples (the loss of the same batch changes) and stays a function of the
// seeds.
TEST(Trainer, RandomYawTurnsTheSamplesDeterministically) {
  const auto data = spinning_cubes(10);
  ModelConfig config = small_model();
  config.noise_std = 1e-3;
  Trainer plain(config, {}, data);
  config.random_yaw = true;
  Trainer a(config, {}, data), b(config, {}, data);
  const double turned = a.step().loss;
  EXPECT_EQ(turned, b.step().loss);
  EXPECT_NE(turned, plain.step().loss);
}

TEST(TrainingBatch, FlagsBodiesThatStayStillAroundTheFrame) {
  auto data = flying_and_resting_cubes(6);
  const double still = kRestSpeed * data[0].time_step;
  EXPECT_EQ(resting_objects(data[0], 3, still), (std::vector<std::uint8_t>{0, 1}));
  // A body that moves in the next step alone is not at rest; kinematic bodies never are.
  data[0].objects[1].poses[4].position.x() += 2 * still;
  EXPECT_EQ(resting_objects(data[0], 3, still), (std::vector<std::uint8_t>{0, 0}));
  EXPECT_EQ(resting_objects(data[0], 2, still), (std::vector<std::uint8_t>{0, 1}));
  data[0].objects[1].kinematic = true;
  EXPECT_EQ(resting_objects(data[0], 2, still), (std::vector<std::uint8_t>{0, 0}));
}

// The rest weight multiplies the resting cube's share of the loss and nothing else: the loss is
// affine in the weight, and weight 0 leaves the flying cube's share alone.
TEST(Trainer, RestLossWeightScalesOnlyTheRestingBodiesShare) {
  const auto data = flying_and_resting_cubes(10);
  auto loss_with = [&](float weight) {
    TrainerConfig trainer_config;
    trainer_config.rest_loss_weight = weight;
    return untrained_loss(trainer_config, data);
  };
  const double flying = loss_with(0.0f), both = loss_with(1.0f), weighted = loss_with(5.0f);
  ASSERT_GT(flying, 0.0);
  ASSERT_GT(both, flying);  // the untrained network does not hold the cube still
  EXPECT_NEAR(weighted - both, 4.0 * (both - flying), 1e-6 * weighted);
}

// A falling cube kicked between frames 3 and 4 (an acceleration of 115 m/s² beyond gravity into
// frame 4) and a resting cube: only the first at frame 3 is an impact; free fall, rest and
// kinematic bodies never are.
std::vector<Trajectory> kicked_and_resting_cubes(int frames) {
  auto data = flying_and_resting_cubes(frames);
  for (int k = 4; k < frames; ++k) data[0].objects[0].poses[k].position.x() += 0.05 * (k - 3);
  return data;
}

TEST(TrainingBatch, MarksImpactsWhereTheCentreDepartsFromGravity) {
  auto data = kicked_and_resting_cubes(8);
  const double still = kRestSpeed * data[0].time_step;
  auto motion_at = [&](int frame) {
    std::vector<std::uint8_t> motion = resting_objects(data[0], frame, still);
    mark_impacts(data[0], frame, kImpactG, motion);
    return motion;
  };
  EXPECT_EQ(motion_at(2), (std::vector<std::uint8_t>{kMoving, kResting}));
  EXPECT_EQ(motion_at(3), (std::vector<std::uint8_t>{kImpact, kResting}));
  EXPECT_EQ(motion_at(4), (std::vector<std::uint8_t>{kMoving, kResting}));
  // The threshold: the kick is 0.05 m / dt² = 115 m/s², between 11 g and 12 g here.
  std::vector<std::uint8_t> motion = resting_objects(data[0], 3, still);
  mark_impacts(data[0], 3, 12.0, motion);
  EXPECT_EQ(motion[0], kMoving);
  mark_impacts(data[0], 3, 11.0, motion);
  EXPECT_EQ(motion[0], kImpact);
  data[0].objects[0].kinematic = true;
  EXPECT_EQ(motion_at(3), (std::vector<std::uint8_t>{kMoving, kResting}));
  std::vector<std::uint8_t> short_flags(1, kMoving);
  EXPECT_THROW(mark_impacts(data[0], 3, kImpactG, short_flags), ConfigError);
}

// The impact weight multiplies the kicked cube's share of the loss at its impact and nothing
// else: the loss over every sample is affine in the weight, and the rest weight's share stays.
TEST(Trainer, ImpactLossWeightScalesOnlyTheImpactsShare) {
  const auto data = kicked_and_resting_cubes(10);
  auto loss_with = [&](float weight) {
    TrainerConfig trainer_config;
    trainer_config.rest_loss_weight = 3.0f;
    trainer_config.impact_loss_weight = weight;
    return untrained_loss(trainer_config, data);
  };
  const double without = loss_with(0.0f), plain = loss_with(1.0f), weighted = loss_with(5.0f);
  ASSERT_GT(without, 0.0);
  ASSERT_GT(plain, without);  // the untrained network does not predict the kick
  EXPECT_NEAR(weighted - plain, 4.0 * (plain - without), 1e-6 * weighted);
  // Weight 1 is a run without the field.
  TrainerConfig rest_only;
  rest_only.rest_loss_weight = 3.0f;
  EXPECT_DOUBLE_EQ(untrained_loss(rest_only, data), plain);
  TrainerConfig bad;
  bad.impact_loss_weight = std::nanf("");
  EXPECT_THROW(Trainer(small_model(), bad, data), ConfigError);
}

// heading_consistency holds each prediction to the prediction for its scene turned about the
// vertical and turned back. The gap a step reports is recomputed here from the model before the
// step: ModelPredictor on the batch's scenes and on their copies turned by the step's angles,
// normalised by the model's target statistics (frozen after the first step).
TEST(Trainer, HeadingGapIsThePredictionsDifferenceFromTheTurnedCopyTurnedBack) {
  const auto data = spinning_cubes(10);
  ModelConfig config = noisy_model();
  config.random_yaw = true;
  config.normalizer_max_accumulations = 1;
  TrainerConfig consistent;
  consistent.batch_size = 2;
  consistent.heading_consistency = 0.5f;
  Trainer trainer(config, consistent, data);
  trainer.step();
  const std::shared_ptr<const Model> before = trainer.current_model();
  const TrainStep step = trainer.step();
  const std::vector<double>& turns = trainer.batch_heading_turns();
  ASSERT_EQ(turns.size(), 2u);
  ModelPredictor predictor(before, PredictionOptions{.threads = 1, .fit_masses = false});
  const Normalizer& normalizer = before->normalizers().target;
  double squares = 0.0;
  Eigen::Index rows = 0;
  for (size_t b = 0; b < turns.size(); ++b) {
    const Scene& scene = trainer.batch_scenes()[b];
    Points straight, turned;
    predictor.predict(scene, straight);
    Scene copy = scene;
    turn_about_vertical(turns[b], copy);
    predictor.predict(copy, turned);
    const Points back = turned * Eigen::AngleAxisd(turns[b], Vec3::UnitZ()).toRotationMatrix();
    RowMatrixXf normalized_straight(straight.rows(), 3), normalized_back(back.rows(), 3);
    normalizer.normalize(straight.cast<float>(), normalized_straight);
    normalizer.normalize(back.cast<float>(), normalized_back);
    squares += (normalized_straight - normalized_back).cast<double>().squaredNorm();
    rows += straight.rows();
  }
  EXPECT_GT(step.heading_gap, 1e-6);
  EXPECT_NEAR(step.heading_gap, squares / (3.0 * rows), 1e-3 * step.heading_gap);
  // Off, nothing is turned or reported.
  Trainer plain(config, {}, data);
  EXPECT_EQ(plain.step().heading_gap, 0.0);
  EXPECT_TRUE(plain.batch_heading_turns().empty());
}

// The term changes the gradient, not the loss a step reports (the fit to the data), and training
// with it leaves predictions that change less with the heading than training without it. Each
// model's gap is read by probes that share one draw and hardly move the parameters.
TEST(Trainer, HeadingConsistencyTrainsTheHeadingGapDown) {
  const auto data = spinning_cubes(12);
  ModelConfig config = small_model();
  config.random_yaw = true;
  TrainerConfig plain;
  plain.batch_size = 4;
  plain.adam.decay_steps = 300;
  TrainerConfig consistent = plain;
  consistent.heading_consistency = 20.0f;
  Trainer without(config, plain, data), with(config, consistent, data);
  EXPECT_EQ(without.step().loss, with.step().loss);
  without.run(300, nullptr);
  with.run(300, nullptr);
  auto gap_of = [&](const Trainer& trained) {
    TrainerConfig probe = consistent;
    probe.adam.learning_rate_start = probe.adam.learning_rate_end = 1e-12f;
    Trainer prober(config, probe, data, trained.model().get());
    double gap = 0.0;
    for (int i = 0; i < 8; ++i) gap += prober.step().heading_gap;
    return gap / 8;
  };
  const double gap_without = gap_of(without), gap_with = gap_of(with);
  EXPECT_LT(gap_with, 0.5 * gap_without) << "without " << gap_without << ", with " << gap_with;
  TrainerConfig bad;
  bad.heading_consistency = -1.0f;
  EXPECT_THROW(Trainer(config, bad, data), ConfigError);
  bad.heading_consistency = std::nanf("");
  EXPECT_THROW(Trainer(config, bad, data), ConfigError);
}

// Both cubes of a frame held still and let go: lifted together until the lower one's lowest
// vertex is `gap` above the floor, their histories still (no noise) or a walk that the target
// undoes (noise, correction 1), and every target row is gravity·dt².
TEST(TrainingBatch, StillSampleInAirHoldsTheBodiesStillAboveTheFloorAndLetsThemFall) {
  auto data = spinning_cubes(8);
  data[0].floor = Floor{0.4};
  const int history = ModelConfig::preset_named("small").graph.history, frame = 4;
  const double gap = 0.03, dt = data[0].time_step;
  const Vec3 fall = Vec3(0, 0, -10) * dt * dt;
  Scene clean;
  scene_at_frame(data[0], frame, history, clean);
  // The clean frame's positions, lifted by one amount so that the lowest vertex sits at the gap.
  double lowest = 1e9;
  for (const SceneObject& object : clean.objects) {
    lowest = std::min(lowest, object.positions_at(history).col(2).minCoeff());
  }
  const Vec3 lift(0, 0, 0.4 + gap - lowest);
  for (NoiseKind kind : {NoiseKind::kVertex, NoiseKind::kRigid}) {
    for (double noise_std : {0.0, 1e-2}) {
      std::mt19937_64 rng(3);
      Scene still;
      Points targets;
      make_still_sample_in_air(data[0], frame, history, gap, noise_std, kind, 1.0, rng, still,
                               targets);
      Eigen::Index row = 0;
      for (size_t o = 0; o < still.objects.size(); ++o) {
        const SceneObject& object = still.objects[o];
        const Eigen::Index v = object.mesh->num_vertices();
        const Points lifted = clean.objects[o].positions_at(history).rowwise() + lift.transpose();
        const Points current = object.positions_at(history);
        const Points next =
            current + (current - object.positions_at(history - 1)) + targets.middleRows(row, v);
        EXPECT_LT((next - (lifted.rowwise() + fall.transpose())).cwiseAbs().maxCoeff(), 1e-12);
        if (noise_std == 0.0) {
          for (int k = 0; k <= history; ++k) {
            EXPECT_LT((object.positions_at(k) - lifted).cwiseAbs().maxCoeff(), 1e-12);
          }
          for (Eigen::Index i = 0; i < v; ++i) {
            EXPECT_LT((targets.row(row + i) - fall.transpose()).norm(), 1e-15);
          }
        } else {
          EXPECT_GT((current - lifted).cwiseAbs().maxCoeff(), 1e-4);  // the noise is there
        }
        row += v;
      }
    }
  }
}

TEST(TrainingBatch, StillSampleInAirRejectsKinematicBodiesAndGapsThatAreNotPositive) {
  auto data = spinning_cubes(8);
  data[0].floor = Floor{};
  std::mt19937_64 rng(3);
  Scene scene;
  Points targets;
  auto make = [&](double gap) {
    make_still_sample_in_air(data[0], 4, 2, gap, 0.0, NoiseKind::kVertex, 0.0, rng, scene, targets);
  };
  EXPECT_THROW(make(0.0), ConfigError);
  EXPECT_THROW(make(std::nan("")), ConfigError);
  EXPECT_TRUE(can_hold_still_in_air(data[0]));
  data[0].objects[1].kinematic = true;
  EXPECT_FALSE(can_hold_still_in_air(data[0]));
  EXPECT_THROW(make(0.1), ConfigError);
}

// With every scene replaced, each node is a still body's and weighs the rest weight: the loss is
// that weight times the unweighted one. Trajectories with kinematic bodies are never replaced.
TEST(Trainer, StillAirSamplesReplaceTheirShareOfScenesAndWeighLikeRestingBodies) {
  auto data = flying_and_resting_cubes(10);
  data[0].floor = Floor{-1.0};
  auto loss_with = [&](float fraction, float rest_weight, const std::vector<Trajectory>& d) {
    TrainerConfig trainer_config;
    trainer_config.still_air_fraction = fraction;
    trainer_config.rest_loss_weight = rest_weight;
    return untrained_loss(trainer_config, d);
  };
  const double plain = loss_with(0.0f, 1.0f, data), still = loss_with(1.0f, 1.0f, data);
  EXPECT_NE(plain, still);
  EXPECT_NEAR(loss_with(1.0f, 5.0f, data), 5.0 * still, 1e-6 * still);
  const double half = loss_with(0.5f, 1.0f, data);
  EXPECT_EQ(half, loss_with(0.5f, 1.0f, data));
  auto with_pusher = data;
  with_pusher[0].objects[0].kinematic = true;
  EXPECT_EQ(loss_with(1.0f, 1.0f, with_pusher), loss_with(0.0f, 1.0f, with_pusher));
  TrainerConfig bad;
  bad.still_air_fraction = 1.5f;
  EXPECT_THROW(Trainer(small_model(), bad, data), ConfigError);
}

// A sample drawn a frame early and advanced to the true poses is the sample of its own frame:
// the history slides, kinematic bodies take their true frames, and the targets are the same.
TEST(TrainingBatch, AdvancingToTheTruthGivesTheSampleOfTheNextFrame) {
  auto data = spinning_cubes(10);
  data[0].objects[1].kinematic = true;
  const int history = ModelConfig::preset_named("small").graph.history, frame = 5;
  std::mt19937_64 rng(3);
  Scene early, expected;
  Points early_targets, expected_targets;
  make_noisy_sample(data[0], frame - 1, history, 0.0, NoiseKind::kRigid, 0.0, rng, early,
                    early_targets);
  make_noisy_sample(data[0], frame, history, 0.0, NoiseKind::kRigid, 0.0, rng, expected,
                    expected_targets);
  std::vector<Pose> truth;
  for (const TrajectoryObject& object : data[0].objects) truth.push_back(object.poses[frame]);
  advance_to_predicted(data[0], frame, history, truth, 0.0, early, early_targets);
  for (size_t o = 0; o < early.objects.size(); ++o) {
    const SceneObject &got = early.objects[o], &want = expected.objects[o];
    EXPECT_LT((got.positions - want.positions).cwiseAbs().maxCoeff(), 1e-12) << o;
    EXPECT_LT((got.centers - want.centers).cwiseAbs().maxCoeff(), 1e-12) << o;
    if (want.kinematic) {
      EXPECT_LT((got.next_positions - want.next_positions).cwiseAbs().maxCoeff(), 1e-12);
    }
  }
  EXPECT_LT((early_targets - expected_targets).cwiseAbs().maxCoeff(), 1e-12);
}

// Advanced to a prediction that is off by a rigid motion, the sample keeps its noisy history
// (one step older), ends at the prediction, and its targets lead to the true next frame plus the
// uncorrected share of the prediction's error: the true velocity is given back.
TEST(TrainingBatch, AdvancingToAWrongPredictionTeachesTheTrueVelocityFromIt) {
  const auto data = spinning_cubes(10);
  const int history = ModelConfig::preset_named("small").graph.history, frame = 6;
  for (double correction : {0.0, 0.5, 1.0}) {
    std::mt19937_64 rng(11);
    Scene scene;
    Points targets;
    make_noisy_sample(data[0], frame - 1, history, 1e-2, NoiseKind::kRigid, correction, rng, scene,
                      targets);
    const Scene early = scene;
    std::vector<Pose> predicted;
    for (const TrajectoryObject& object : data[0].objects) {
      Pose pose = object.poses[frame];
      pose.position += Vec3(0.01, -0.02, 0.03);
      pose.orientation = Eigen::AngleAxisd(0.05, Vec3(1, 2, 3).normalized()) * pose.orientation;
      predicted.push_back(pose);
    }
    advance_to_predicted(data[0], frame, history, predicted, correction, scene, targets);
    Eigen::Index row = 0;
    for (size_t o = 0; o < scene.objects.size(); ++o) {
      const SceneObject& object = scene.objects[o];
      const TriangleMesh& mesh = *object.mesh;
      const Eigen::Index v = mesh.num_vertices();
      for (int k = 0; k < history; ++k) {
        EXPECT_EQ(object.positions_at(k), early.objects[o].positions_at(k + 1)) << k;
      }
      const Points now = posed_vertices(mesh, predicted[o]);
      EXPECT_LT((object.positions_at(history) - now).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_LT((object.centers.row(history).transpose() - predicted[o].position).norm(), 1e-12);
      const Points error = now - posed_vertices(mesh, data[0].objects[o].poses[frame]);
      const Points next = 2.0 * now - object.positions_at(history - 1) + targets.middleRows(row, v);
      const Points true_next = posed_vertices(mesh, data[0].objects[o].poses[frame + 1]);
      EXPECT_LT((next - (true_next + (1.0 - correction) * error)).cwiseAbs().maxCoeff(), 1e-12)
          << "object " << o << ", correction " << correction;
      row += v;
    }
  }
  Scene scene;
  Points targets;
  std::mt19937_64 rng(1);
  make_noisy_sample(data[0], history, history, 0.0, NoiseKind::kRigid, 0.0, rng, scene, targets);
  const std::vector<Pose> one(1);
  EXPECT_THROW(advance_to_predicted(data[0], history + 1, history, one, 0.0, scene, targets),
               ConfigError);
  const std::vector<Pose> two(2);
  EXPECT_THROW(advance_to_predicted(data[0], history, history, two, 0.0, scene, targets),
               ConfigError);
}

// The trainer's last batch's scene b and its target rows within float tolerance of an oracle's.
void expect_batch_scene_near(const Trainer& trainer, size_t b, const Scene& expected,
                             const Points& expected_targets) {
  const Scene& got = trainer.batch_scenes()[b];
  for (size_t o = 0; o < got.objects.size(); ++o) {
    EXPECT_LT((got.objects[o].positions - expected.objects[o].positions).cwiseAbs().maxCoeff(),
              1e-6)
        << "scene " << b << ", object " << o;
  }
  EXPECT_LT((trainer.batch_targets()[b] - expected_targets).cwiseAbs().maxCoeff(), 1e-6) << b;
}

// A pushed step trains on the scene advanced to what the network itself predicts from the frame
// before: the same as predicting that frame with a ModelPredictor of the trainer's model (the
// inference path, apart from the trainer's) and advancing the sample to it.
TEST(Trainer, PushforwardTrainsOnTheNetworksOwnPrediction) {
  const auto data = spinning_cubes(10);
  const int h = noisy_model().graph.history;
  const std::vector<SampleRef> samples = {{0, 6}, {0, 4}};
  TrainerConfig pushing;
  pushing.batch_size = 2;
  pushing.pushforward_fraction = 1.0f;
  Trainer trainer(noisy_model(), pushing, data);
  const std::shared_ptr<const Model> before = trainer.current_model();
  trainer.step_on(samples, 7);
  ASSERT_EQ(trainer.batch_pushed(), (std::vector<std::uint8_t>{1, 1}));
  // The same draw unpushed, a frame early: the scenes the network saw (same noise seeds).
  Trainer plain(noisy_model(), {}, data);
  plain.step_on({{0, 5}, {0, 3}}, 7);
  ModelPredictor predictor(before, PredictionOptions{.threads = 1, .fit_masses = false});
  for (size_t b = 0; b < samples.size(); ++b) {
    Scene expected = plain.batch_scenes()[b];
    Points expected_targets = plain.batch_targets()[b];
    std::vector<Pose> next;
    StepWorkspace workspace;
    predict_next_poses(predictor, expected, next, workspace);
    advance_to_predicted(data[0], samples[b].frame, h, next, 0.0, expected, expected_targets);
    expect_batch_scene_near(trainer, b, expected, expected_targets);
  }
  // The prediction is not the truth: the pushed samples differ from their frames' own.
  plain.step_on(samples, 7);
  for (size_t b = 0; b < samples.size(); ++b) {
    EXPECT_GT((trainer.batch_targets()[b] - plain.batch_targets()[b]).cwiseAbs().maxCoeff(), 1e-4);
  }
  // The first frame with a history has no frame before it to push from.
  trainer.step_on({{0, h}, {0, 6}}, 7);
  EXPECT_EQ(trainer.batch_pushed(), (std::vector<std::uint8_t>{0, 1}));
}

// pushforward_steps: a pushed scene is drawn that many frames early (fewer where the first frame
// with a history comes sooner) and rolled out by the network to its own frame, each step as
// ModelPredictor predicts it and advance_to_predicted moves it on; a scene at the first frame
// with a history is not pushed.
TEST(Trainer, PushforwardStepsRollsAPushedSceneOutToItsFrame) {
  const auto data = spinning_cubes(10);
  const int h = noisy_model().graph.history;
  const std::vector<SampleRef> samples = {{0, h + 3}, {0, h + 1}, {0, h}};
  TrainerConfig pushing;
  pushing.batch_size = 3;
  pushing.pushforward_fraction = 1.0f;
  pushing.pushforward_steps = 3;
  Trainer trainer(noisy_model(), pushing, data);
  const std::shared_ptr<const Model> before = trainer.current_model();
  trainer.step_on(samples, 7);
  ASSERT_EQ(trainer.batch_pushed(), (std::vector<std::uint8_t>{3, 1, 0}));
  // The oracle: the same draw unpushed at the frames the pushed scenes start from (same noise
  // seeds), then one prediction and advance per frame.
  Trainer plain(noisy_model(), {}, data);
  plain.step_on({{0, h}, {0, h}, {0, h}}, 7);
  ModelPredictor predictor(before, PredictionOptions{.threads = 1, .fit_masses = false});
  for (size_t b = 0; b < samples.size(); ++b) {
    Scene expected = plain.batch_scenes()[b];
    Points expected_targets = plain.batch_targets()[b];
    for (int frame = h + 1; frame <= samples[b].frame; ++frame) {
      std::vector<Pose> next;
      StepWorkspace workspace;
      predict_next_poses(predictor, expected, next, workspace);
      advance_to_predicted(data[0], frame, h, next, 0.0, expected, expected_targets);
    }
    expect_batch_scene_near(trainer, b, expected, expected_targets);
  }
  // Three steps of the network's own error are not one: the first scene differs from a push of
  // one frame.
  pushing.pushforward_steps = 1;
  Trainer one(noisy_model(), pushing, data);
  one.step_on(samples, 7);
  ASSERT_EQ(one.batch_pushed(), (std::vector<std::uint8_t>{1, 1, 0}));
  EXPECT_GT((trainer.batch_targets()[0] - one.batch_targets()[0]).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(trainer.batch_targets()[1], one.batch_targets()[1]);
  for (int steps : {0, kMaxPushforwardSteps + 1}) {
    pushing.pushforward_steps = steps;
    EXPECT_THROW(Trainer(noisy_model(), pushing, data), ConfigError) << steps;
  }
}

// pushforward_skips_rest: in a pushed scene the body at rest in the data is advanced to its true
// frame and the flying one to the network's prediction, as advance_to_predicted makes them from
// the scene drawn a frame early (the rest flags come from the skip alone: rest weight 1).
TEST(Trainer, PushforwardSkipsRestAdvancesRestingBodiesToTheTruth) {
  const auto data = flying_and_resting_cubes(10);
  const int h = noisy_model().graph.history;
  const std::vector<SampleRef> samples = {{0, 6}};
  TrainerConfig pushing;
  pushing.batch_size = 1;
  pushing.rest_loss_weight = 1.0f;
  pushing.pushforward_fraction = 1.0f;
  TrainerConfig skipping = pushing;
  skipping.pushforward_skips_rest = true;
  Trainer all(noisy_model(), pushing, data), skip(noisy_model(), skipping, data);
  const std::shared_ptr<const Model> before = skip.current_model();
  all.step_on(samples, 7);
  skip.step_on(samples, 7);
  ASSERT_EQ(skip.batch_pushed(), std::vector<std::uint8_t>{1});
  // The oracle: the same draw a frame early, predicted, the resting cube put back on the truth.
  Trainer plain(noisy_model(), {}, data);
  plain.step_on({{0, 5}}, 7);
  ModelPredictor predictor(before, PredictionOptions{.threads = 1, .fit_masses = false});
  Scene expected = plain.batch_scenes()[0];
  Points expected_targets = plain.batch_targets()[0];
  std::vector<Pose> next;
  StepWorkspace workspace;
  predict_next_poses(predictor, expected, next, workspace);
  next[1] = data[0].objects[1].poses[6];
  advance_to_predicted(data[0], 6, h, next, 0.0, expected, expected_targets);
  const Scene& got = skip.batch_scenes()[0];
  for (size_t o = 0; o < 2; ++o) {
    EXPECT_LT((got.objects[o].positions - expected.objects[o].positions).cwiseAbs().maxCoeff(),
              1e-6)
        << "object " << o;
  }
  EXPECT_LT((skip.batch_targets()[0] - expected_targets).cwiseAbs().maxCoeff(), 1e-6);
  // The flying cube is pushed alike either way; the resting one only without the skip moves
  // off the truth.
  const Scene& pushed = all.batch_scenes()[0];
  EXPECT_EQ(got.objects[0].positions, pushed.objects[0].positions);
  EXPECT_GT((pushed.objects[1].positions - got.objects[1].positions).cwiseAbs().maxCoeff(), 1e-7);
}

// With random_yaw a pushed scene is advanced unturned (the truth it advances by is unturned) and
// turned after: it is the unturned run's pushed scene and targets turned by one angle.
TEST(Trainer, APushedSceneIsTurnedAfterItsPush) {
  const auto data = spinning_cubes(10);
  const std::vector<SampleRef> samples = {{0, 6}, {0, 4}};
  TrainerConfig pushing;
  pushing.batch_size = 2;
  pushing.pushforward_fraction = 1.0f;
  ModelConfig config = noisy_model();
  Trainer straight(config, pushing, data);
  config.random_yaw = true;
  Trainer turned(config, pushing, data);
  straight.step_on(samples, 7);
  turned.step_on(samples, 7);
  ASSERT_EQ(turned.batch_pushed(), (std::vector<std::uint8_t>{1, 1}));
  for (size_t b = 0; b < samples.size(); ++b) {
    const Scene& unturned = straight.batch_scenes()[b];
    const Scene& got = turned.batch_scenes()[b];
    // The angle that takes the first node's offset from the turning axis to its turned one.
    const Vec3 axis = unturned.floor ? Vec3(unturned.floor->center_x, unturned.floor->center_y, 0.0)
                                     : Vec3::Zero();
    const Vec3 from = unturned.objects[0].positions.row(0).transpose() - axis;
    const Vec3 to = got.objects[0].positions.row(0).transpose() - axis;
    const double angle =
        std::atan2(from.x() * to.y() - from.y() * to.x(), from.x() * to.x() + from.y() * to.y());
    ASSERT_GT(std::abs(angle), 1e-3) << "scene " << b << " was not turned";
    Scene expected = unturned;
    Points expected_targets = straight.batch_targets()[b];
    turn_about_vertical(angle, expected, expected_targets);
    for (size_t o = 0; o < got.objects.size(); ++o) {
      EXPECT_LT((got.objects[o].positions - expected.objects[o].positions).cwiseAbs().maxCoeff(),
                1e-9)
          << "scene " << b << ", object " << o;
      EXPECT_LT((got.objects[o].centers - expected.objects[o].centers).cwiseAbs().maxCoeff(), 1e-9)
          << "scene " << b << ", object " << o;
    }
    EXPECT_LT((turned.batch_targets()[b] - expected_targets).cwiseAbs().maxCoeff(), 1e-9) << b;
  }
}

// Pushing a share of the steps: chosen per step from the step's draw, the other steps unchanged
// (the same scenes and targets as a run without it), and the statistics warm-up never pushed.
TEST(Trainer, PushforwardFractionPushesItsShareOfStepsAndLeavesTheOthersAsTheyWere) {
  const auto data = spinning_cubes(12);
  TrainerConfig half;
  half.batch_size = 3;
  half.pushforward_fraction = 0.5f;
  TrainerConfig none = half;
  none.pushforward_fraction = 0.0f;
  Trainer pushing(noisy_model(), half, data), plain(noisy_model(), none, data);
  pushing.warm_up_statistics(2);
  plain.warm_up_statistics(2);
  EXPECT_EQ(pushing.normalizers().target.mean(), plain.normalizers().target.mean());
  int pushed_steps = 0;
  // Targets come from the data and the noise alone: an unpushed step's match whatever the
  // parameters, a pushed step's differ where its scenes were pushed.
  for (int i = 0; i < 12; ++i) {
    pushing.step();
    plain.step();
    const bool pushed = std::ranges::any_of(pushing.batch_pushed(), [](auto p) { return p != 0; });
    pushed_steps += pushed ? 1 : 0;
    for (size_t b = 0; b < 3; ++b) {
      EXPECT_EQ(pushing.batch_targets()[b] == plain.batch_targets()[b], !pushing.batch_pushed()[b])
          << "step " << i << ", scene " << b;
    }
  }
  EXPECT_GT(pushed_steps, 0);
  EXPECT_LT(pushed_steps, 12);
  TrainerConfig bad;
  bad.pushforward_fraction = -0.5f;
  EXPECT_THROW(Trainer(small_model(), bad, data), ConfigError);
}

TEST(Trainer, IsDeterministicForASeed) {
  const auto data = spinning_cubes(10);
  ModelConfig config = small_model();
  config.noise_std = 1e-3;
  Trainer a(config, {}, data), b(config, {}, data);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(a.step().loss, b.step().loss);
  EXPECT_EQ(a.parameters(), b.parameters());
  TrainerConfig other;
  other.seed = 2;
  Trainer c(config, other, data);
  for (int i = 0; i < 5; ++i) c.step();
  EXPECT_NE(a.parameters(), c.parameters());
}

TEST(Trainer, RejectsDataWithoutSamples) {
  EXPECT_THROW(Trainer(small_model(), {}, spinning_cubes(3)), ConfigError);
}

TEST(Model, RolloutThroughAModelIsFiniteAndCountsFaceEdges) {
  auto data = spinning_cubes(10);
  // A floor 5 cm below the first cube's lowest vertex at frame 2, the first frame predicted from.
  const TrajectoryObject& cube = data[0].objects[0];
  const Points posed =
      cube.mesh->vertices() * cube.poses[2].orientation.toRotationMatrix().transpose();
  data[0].floor = Floor{cube.poses[2].position.z() + posed.col(2).minCoeff() - 0.05};
  Trainer trainer(small_model(), {}, data);
  trainer.run(3, nullptr);
  ModelPredictor predictor(trainer.model());
  std::vector<int> face_edges;
  const Trajectory predicted = rollout(predictor, data[0], -1, &face_edges);
  ASSERT_EQ(face_edges.size(), 10u - 3u);  // frames 3 … 9 are predicted
  for (const TrajectoryObject& object : predicted.objects) {
    for (const Pose& pose : object.poses) {
      EXPECT_TRUE(pose.position.allFinite());
      EXPECT_NEAR(pose.orientation.norm(), 1.0, 1e-9);
    }
  }
  EXPECT_GT(face_edges.front(), 0);  // cube–floor face pairs within d_c = 0.1 m
}

// A model of small_model()'s with random weights (model_fixtures.h).
std::shared_ptr<const Model> random_model(const Scene& scene) {
  ModelConfig config = small_model();
  config.latent_size = 16;
  return testing::random_model(scene, config);
}

TEST(Model, OutputIsEquivariantToObjectOrder) {
  auto fixture = testing::make_random_scene(13, 5, 0.6);
  ModelPredictor predictor(random_model(fixture.scene));
  Points original, permuted;
  predictor.predict(fixture.scene, original);
  Scene reversed = fixture.scene;
  std::reverse(reversed.objects.begin(), reversed.objects.end());
  predictor.predict(reversed, permuted);
  // Object o's rows in the reversed scene start after all the objects that now precede it.
  std::vector<Eigen::Index> first(fixture.scene.objects.size() + 1, 0), first_rev(first);
  const int n = static_cast<int>(fixture.scene.objects.size());
  for (int o = 0; o < n; ++o)
    first[o + 1] = first[o] + fixture.scene.objects[o].mesh->num_vertices();
  for (int o = 0; o < n; ++o)
    first_rev[o + 1] = first_rev[o] + reversed.objects[o].mesh->num_vertices();
  for (int o = 0; o < n; ++o) {
    const int v = fixture.scene.objects[o].mesh->num_vertices();
    const auto a = original.middleRows(first[o], v);
    const auto b = permuted.middleRows(first_rev[n - 1 - o], v);
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-5 * (1.0 + a.cwiseAbs().maxCoeff()))
        << "object " << o;
  }
}

// Largest difference of the predictions of `scene` and of `scene` turned by `angle` about the
// vertical, the second turned back, relative to the first's largest value.
double turned_prediction_difference(ModelPredictor& predictor, const Scene& scene, double angle) {
  Points direct, turned;
  predictor.predict(scene, direct);
  Scene copy = scene;
  turn_about_vertical(angle, copy);
  predictor.predict(copy, turned);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  return (turned * turn - direct).cwiseAbs().maxCoeff() / direct.cwiseAbs().maxCoeff();
}

TEST(ModelPredictor, PredictionsAveragedOverTurnsTurnWithTheScene) {
  // Averaged over k/n turns, a prediction is equivariant to those turns, whatever the weights; a
  // single one is not. The scenes have collision edges but no overlapping faces: the closest
  // points of two crossing triangles jump with rounding, so that even a full turn changes such a
  // scene's prediction. The mesh floor's two triangles map onto themselves under a half turn
  // about its centre, not under a quarter turn: the quarter-turn scene's bodies are off the floor.
  const auto on_floor = testing::make_random_scene(13, 5, 2.0);
  const auto in_air = testing::make_random_scene(17, 5, 2.0);
  auto model = random_model(on_floor.scene);
  const double half = std::numbers::pi, quarter = std::numbers::pi / 2;
  ModelPredictor single(model), two(model, {.turns = 2}), four(model, {.turns = 4});
  EXPECT_LT(turned_prediction_difference(single, on_floor.scene, 2 * half), 1e-12);
  EXPECT_GT(single.last_face_edges(), 0);
  EXPECT_LT(turned_prediction_difference(single, in_air.scene, 2 * half), 1e-12);
  EXPECT_GT(single.last_face_edges(), 0);

  EXPECT_GT(turned_prediction_difference(single, on_floor.scene, half), 1e-2);
  EXPECT_LT(turned_prediction_difference(two, on_floor.scene, half), 1e-5);
  EXPECT_GT(turned_prediction_difference(two, in_air.scene, quarter), 1e-2);
  EXPECT_LT(turned_prediction_difference(four, in_air.scene, quarter), 1e-5);
  EXPECT_LT(turned_prediction_difference(four, in_air.scene, half), 1e-5);
}

// `scene` seen in a mirror through the plane y = 0 (its floor's centre lies on it), with the
// mirrored meshes it needs.
struct MirroredScene {
  std::vector<std::unique_ptr<const TriangleMesh>> meshes;
  Scene scene;
};

MirroredScene mirror_of(const Scene& scene) {
  MirroredScene result;
  result.scene = scene;
  map_about_vertical(Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal().toDenseMatrix(), result.scene);
  for (SceneObject& object : result.scene.objects) {
    result.meshes.push_back(std::make_unique<const TriangleMesh>(mirrored_mesh(*object.mesh)));
    object.mesh = result.meshes.back().get();
  }
  return result;
}

TEST(ModelPredictor, PredictionsAveragedWithTheMirrorReflectWithTheScene) {
  // Averaged with the mirrored scene's, a prediction is equivariant to the reflection whatever
  // the weights, and with turns to the turns as well; a single one is neither.
  const auto fixture = testing::make_random_scene(17, 5, 2.0);
  auto model = random_model(fixture.scene);
  const MirroredScene mirrored = mirror_of(fixture.scene);
  const Eigen::Matrix3d reflect = Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal();
  auto reflected_difference = [&](ModelPredictor& predictor) {
    Points direct, image;
    predictor.predict(fixture.scene, direct);
    predictor.predict(mirrored.scene, image);
    return (image * reflect - direct).cwiseAbs().maxCoeff() / direct.cwiseAbs().maxCoeff();
  };
  ModelPredictor single(model), mirror(model, {.mirror = true}),
      four_mirrored(model, {.turns = 4, .mirror = true});
  EXPECT_GT(reflected_difference(single), 1e-2);
  EXPECT_GT(single.last_face_edges(), 0);
  EXPECT_LT(reflected_difference(mirror), 1e-5);
  EXPECT_LT(reflected_difference(four_mirrored), 1e-5);
  EXPECT_LT(turned_prediction_difference(four_mirrored, fixture.scene, std::numbers::pi / 2), 1e-5);
  // The mirrored copy is no turn: turns alone leave the reflection's difference.
  ModelPredictor two(model, {.turns = 2});
  EXPECT_GT(reflected_difference(two), 1e-2);
}

TEST(ModelPredictor, MirrorsFollowMeshesThatComeAndGo) {
  // One predictor over scenes whose meshes are made and freed in turn (new meshes often at a
  // freed one's address; the mirrors of meshes no longer seen are let go once they pile up):
  // each prediction is a fresh predictor's.
  auto model = random_model(testing::make_random_scene(13, 3, 0.6).scene);
  ModelPredictor kept(model, {.mirror = true});
  for (unsigned seed = 0; seed < 30; ++seed) {
    SCOPED_TRACE(::testing::Message() << "scene " << seed);
    const auto fixture = testing::make_random_scene(100 + seed, 3, 0.6);
    Points expected, predicted;
    ModelPredictor(model, {.mirror = true}).predict(fixture.scene, expected);
    kept.predict(fixture.scene, predicted);
    ASSERT_EQ(predicted.rows(), expected.rows());
    EXPECT_LT((predicted - expected).cwiseAbs().maxCoeff(), 1e-6 * expected.cwiseAbs().maxCoeff());
  }
}

TEST(ModelPredictor, TurnedCopiesOnSeveralThreadsPredictAsOnOne) {
  // With threads other than 1 the turned (and mirrored) copies run one per thread, each on its own
  // builder, graph and workspace: the same predictions as one after another (products on one thread
  // each against products shared out: float tolerance), and last_graph() still the scene's own, for
  // the plain build, Bullet's candidate pairs and the free-flight split.
  const auto fixture = testing::make_random_scene(13, 5, 2.0);
  auto model = random_model(fixture.scene);
  std::vector<ObjectPair> all_pairs;
  const int n = static_cast<int>(fixture.scene.objects.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) all_pairs.push_back({a, b});
  }
  for (const auto& [free_flight, mirror] :
       {std::pair(false, false), {true, false}, {false, true}, {true, true}}) {
    for (const bool with_candidates : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "free_flight " << free_flight << ", mirror " << mirror
                                        << ", candidates " << with_candidates);
      const PredictionOptions options{
          .threads = 1, .turns = 4, .mirror = mirror, .free_flight = free_flight};
      ModelPredictor one(model, options);
      Points expected, predicted;
      auto predict = [&](ModelPredictor& predictor, Points& out) {
        if (with_candidates) {
          predictor.predict_with_candidates(fixture.scene, all_pairs, out);
        } else {
          predictor.predict(fixture.scene, out);
        }
      };
      predict(one, expected);
      for (const int threads : {2, 3}) {
        PredictionOptions on_threads = options;
        on_threads.threads = threads;
        ModelPredictor several(model, on_threads);
        for (int step = 0; step < 2; ++step) {  // the second reuses every copy's buffers
          predict(several, predicted);
          ASSERT_EQ(predicted.rows(), expected.rows());
          EXPECT_LT((predicted - expected).cwiseAbs().maxCoeff(),
                    1e-5 * expected.cwiseAbs().maxCoeff());
          EXPECT_EQ(several.last_graph().num_mesh_nodes(), one.last_graph().num_mesh_nodes());
          EXPECT_EQ(several.last_face_edges(), one.last_face_edges());
        }
      }
    }
  }
}

TEST(ModelPredictor, TurnAveragingCancelsAConstantHorizontalBias) {
  // Zero weights: the network's output is 0 in normalised units, so every node is predicted the
  // target normaliser's mean b (std 1). Turned back, the half-turned scene's prediction is
  // (−b_x, −b_y, b_z): the average keeps b_z alone.
  auto fixture = testing::make_random_scene(7, 3, 0.6);
  const ModelConfig config = small_model();
  const Model fresh(config);
  Normalizers normalizers = fresh.normalizers();
  const Eigen::Vector3d bias(0.3, -0.2, -4.0);
  normalizers.target.set_state(1, 1.0, bias, bias.cwiseAbs2().array() + 1.0);
  auto model = std::make_shared<const Model>(
      config, std::vector<float>(fresh.parameters().size(), 0.0f), normalizers);
  Points single, averaged;
  ModelPredictor(model).predict(fixture.scene, single);
  ModelPredictor(model, {.turns = 2}).predict(fixture.scene, averaged);
  for (Eigen::Index i = 0; i < single.rows(); ++i) {
    EXPECT_NEAR((single.row(i).transpose() - bias).norm(), 0.0, 1e-6);
    EXPECT_NEAR((averaged.row(i).transpose() - Vec3(0, 0, bias.z())).norm(), 0.0, 1e-6);
  }
}

TEST(MassFit, TheFactorNearestOneThatFitsTheSceneWithinTheTrainingMasses) {
  Scene scene;
  for (const auto& [mass, kinematic] : {std::pair(2.0, false), {8.0, false}, {0.0, true}}) {
    scene.objects.emplace_back().properties.mass = mass;
    scene.objects.back().kinematic = kinematic;
  }
  scene.objects.emplace_back().properties.mass = 1e6;  // a kinematic body's mass counts for
  scene.objects.back().kinematic = true;               // nothing: it cannot be moved anyway
  EXPECT_EQ(mass_fit_factor(scene, 1.0, 10.0), 1.0);   // within: untouched
  EXPECT_EQ(mass_fit_factor(scene, 2.0, 8.0), 1.0);
  EXPECT_DOUBLE_EQ(mass_fit_factor(scene, 100.0, 1000.0), 50.0);   // the lightest lifted to 100
  EXPECT_DOUBLE_EQ(mass_fit_factor(scene, 0.01, 0.1), 0.1 / 8.0);  // the heaviest down to 0.1
  // A span of 4 into one of 2: the geometric means meet, sqrt(2·8)·f = sqrt(1·2).
  EXPECT_DOUBLE_EQ(mass_fit_factor(scene, 1.0, 2.0), std::sqrt(2.0) / 4.0);
  EXPECT_EQ(mass_fit_factor(scene, 0.0, 0.0), 1.0);  // a model that does not know its masses
  Scene kinematic_only;
  kinematic_only.objects.emplace_back().kinematic = true;
  EXPECT_EQ(mass_fit_factor(kinematic_only, 100.0, 1000.0), 1.0);
}

TEST(ModelPredictor, MassesOutsideTheTrainingDataAreFittedByOneCommonFactor) {
  // Bodies of 1, 2, 4 and 5 kg (and kinematic ones) for a model that knows 1-10 kg: scaled by
  // 1000 or 100,000 the network sees the scene doubled (heaviest 10 kg) both times.
  auto fixture = testing::make_random_scene(13, 5, 0.6);
  const auto model_of = [&](double min_mass, double max_mass) {
    const auto random = random_model(fixture.scene);
    ModelConfig config = random->config();
    config.min_mass = min_mass;
    config.max_mass = max_mass;
    return std::make_shared<const Model>(config, random->parameters(), random->normalizers());
  };
  const auto scaled = [&](double factor) {
    Scene scene = fixture.scene;
    for (SceneObject& object : scene.objects) object.properties.mass *= factor;
    return scene;
  };
  const auto prediction = [](ModelPredictor&& predictor, const Scene& scene) {
    Points accelerations;
    predictor.predict(scene, accelerations);
    return accelerations;
  };
  const auto knowing = model_of(1.0, 10.0);
  const Points doubled = prediction(ModelPredictor(knowing), scaled(2.0));
  const double size = doubled.cwiseAbs().maxCoeff();
  for (const double factor : {1e3, 1e5}) {
    const Points fitted = prediction(ModelPredictor(knowing), scaled(factor));
    EXPECT_LT((fitted - doubled).cwiseAbs().maxCoeff(), 1e-6 * size) << factor;
    const Points unfitted =
        prediction(ModelPredictor(knowing, {.fit_masses = false}), scaled(factor));
    EXPECT_GT((unfitted - doubled).cwiseAbs().maxCoeff(), 1e-2 * size) << factor;
  }
  // Within the training masses, or for a model without them, the scene is the network's as is.
  const Points original = prediction(ModelPredictor(knowing, {.fit_masses = false}), fixture.scene);
  EXPECT_EQ(prediction(ModelPredictor(knowing), fixture.scene), original);
  EXPECT_EQ(prediction(ModelPredictor(model_of(0.0, 0.0)), fixture.scene), original);
  EXPECT_GT(
      (prediction(ModelPredictor(model_of(0.0, 0.0)), scaled(1e3)) - doubled).cwiseAbs().maxCoeff(),
      1e-2 * size);
}

TEST(ModelPredictor, RejectsTurnsBelowOne) {
  auto fixture = testing::make_random_scene(7, 2, 0.6);
  auto model = random_model(fixture.scene);
  EXPECT_THROW(ModelPredictor(model, {.turns = 0}), ConfigError);
}

}  // namespace
}  // namespace fignet
