// one_step_totals against a hand-built drop: a cube falls under gravity, hits the floor and stays.
// Which steps are free flight, contact or rest, and which impacts had no collision edge, follow
// from the cube's height alone (its faces are parallel to the floor), computed here directly.
#include <gtest/gtest.h>

#include "fignet/error.h"
#include "fignet/rollout/one_step.h"
#include "trajectory_fixtures.h"

namespace fignet {
namespace {

TEST(OneStep, RegimesAndUnseenImpactsOfADrop) {
  const double dt = 1.0 / 48.0, half = 0.2, radius = 0.1;
  const Vec3 g(0, 0, -10);
  const int frames = 60;
  Trajectory truth;
  truth.time_step = dt;
  truth.gravity = g;
  truth.floor = Floor{};
  // 3 m/s down from 2.6 m (the last free frame has the bottom 0.13 m up) until the cube meets the
  // floor; then it slides along x from 2 m/s, slowed by 3 m/s² of friction, and stops.
  std::vector<Vec3> x(frames);
  int landed = -1;
  for (int f = 0; f < frames; ++f) {
    const double t = f * dt;
    x[f] = Vec3(0, 0, std::max(half, 2.6 - 3.0 * t - 5.0 * t * t));
    if (x[f].z() == half && landed < 0) landed = f;
    if (landed >= 0) {
      const double s = std::min((f - landed) * dt, 2.0 / 3.0);
      x[f].x() = 2.0 * s - 1.5 * s * s;
    }
  }
  TrajectoryObject cube = testing::ballistic_object(testing::small_cube(half), Vec3::Zero(),
                                                    Vec3::Zero(), Vec3::Zero(), frames, dt, g);
  for (int f = 0; f < frames; ++f) cube.poses[f].position = x[f];
  truth.objects.push_back(cube);

  GravityPredictor ballistic(g, dt, 2);
  GraphConfig graph;
  graph.collision_radius = radius;
  const Vec3 sigma(0.5, 0.5, 2.0);
  const std::vector<Trajectory> set = {truth};
  const OneStepTotals totals = one_step_totals(ballistic, graph, sigma, set);

  // The oracle: edge iff the bottom is within d_c; rest iff in contact and still over the step.
  OneStepTotals expected;
  for (int t = 2; t + 1 < frames; ++t) {
    const bool edge = x[t].z() - half < radius;
    const Vec3 error = 2 * x[t] - x[t - 1] + g * dt * dt - x[t + 1];
    const double speed = (x[t + 1] - x[t]).norm() / dt;
    const Regime regime = !edge          ? Regime::kFreeFlight
                          : speed < 0.05 ? Regime::kRest
                                         : Regime::kContact;
    RegimeTotals& r = expected.regimes[static_cast<int>(regime)];
    r.samples += 1;
    r.translation += error.norm();
    // Every one of the 8 vertices errs by the same vector.
    r.squared_sigmas += 8 * error.cwiseQuotient(sigma).squaredNorm();
    r.components += 24;
    // Signed: along the motion into the step, and upward (gravity is -z).
    const Vec3 incoming = x[t] - x[t - 1];
    const double ahead = incoming.norm() > 0 ? error.dot(incoming.normalized()) : 0.0;
    r.ahead += ahead;
    r.up += error.z();
    const Vec3 acceleration = (x[t + 1] - 2 * x[t] + x[t - 1]) / (dt * dt);
    if ((acceleration - g).norm() > 2 * g.norm()) {
      if (!edge) expected.unseen_impacts += 1;
      expected.impact_errors.samples += 1;
      expected.impact_errors.translation += error.norm();
      expected.impact_errors.ahead += ahead;
      expected.impact_errors.up += error.z();
    }
  }
  ASSERT_GT(expected.unseen_impacts, 0) << "the drop should hit the floor from beyond d_c";
  for (int r = 0; r < kRegimes; ++r) {
    SCOPED_TRACE(std::string(regime_name(static_cast<Regime>(r))));
    ASSERT_GT(expected.regimes[r].samples, 0);
    EXPECT_EQ(totals.regimes[r].samples, expected.regimes[r].samples);
    EXPECT_NEAR(totals.regimes[r].translation, expected.regimes[r].translation, 1e-9);
    EXPECT_NEAR(totals.regimes[r].rotation, 0.0, 1e-6);
    EXPECT_NEAR(totals.regimes[r].squared_sigmas, expected.regimes[r].squared_sigmas, 1e-9);
    EXPECT_EQ(totals.regimes[r].components, expected.regimes[r].components);
    EXPECT_NEAR(totals.regimes[r].ahead, expected.regimes[r].ahead, 1e-9);
    EXPECT_NEAR(totals.regimes[r].up, expected.regimes[r].up, 1e-9);
  }
  // Ballistic through a landing and a slide: it keeps going where the floor and friction stop
  // the truth (ahead > 0), and falls below where the floor holds it (up < 0).
  EXPECT_GT(mean_ahead(totals.regimes[1]), 0.0);
  EXPECT_LT(mean_up(totals.regimes[1]), 0.0);
  ASSERT_GT(expected.impact_errors.samples, 0);
  EXPECT_EQ(totals.impact_errors.samples, expected.impact_errors.samples);
  EXPECT_NEAR(totals.impact_errors.translation, expected.impact_errors.translation, 1e-9);
  EXPECT_NEAR(totals.impact_errors.ahead, expected.impact_errors.ahead, 1e-9);
  EXPECT_NEAR(totals.impact_errors.up, expected.impact_errors.up, 1e-9);
  // The ballistic predictor errs in free flight only at the unseen impact, by the floor's stop.
  const int impact = landed - 1;
  EXPECT_NEAR(totals.regimes[0].translation,
              (2 * x[impact] - x[impact - 1] + g * dt * dt - x[landed]).norm(), 1e-9);
  EXPECT_EQ(totals.unseen_impacts, expected.unseen_impacts);

  // Shares add up, and the flat form round-trips.
  OneStepTotals twice = totals;
  twice += OneStepTotals::deserialize(totals.serialize());
  EXPECT_EQ(twice.regimes[2].samples, 2 * totals.regimes[2].samples);
  EXPECT_EQ(twice.unseen_impacts, 2 * totals.unseen_impacts);
  EXPECT_NEAR(twice.regimes[1].ahead, 2 * totals.regimes[1].ahead, 1e-12);
  EXPECT_EQ(twice.impact_errors.samples, 2 * totals.impact_errors.samples);
  EXPECT_NEAR(twice.impact_errors.up, 2 * totals.impact_errors.up, 1e-12);
  EXPECT_THROW(OneStepTotals::deserialize(std::vector<double>(3)), ConfigError);

  // Shared among threads, each with its own predictor: the same sums.
  const std::vector<Trajectory> three = {truth, truth, truth};
  const OneStepTotals threaded = one_step_totals_parallel(
      [&] { return std::make_unique<GravityPredictor>(g, dt, 2); }, graph, sigma, three, 2);
  for (int r = 0; r < kRegimes; ++r) {
    EXPECT_EQ(threaded.regimes[r].samples, 3 * totals.regimes[r].samples);
    EXPECT_NEAR(threaded.regimes[r].translation, 3 * totals.regimes[r].translation, 1e-9);
    EXPECT_NEAR(mean_translation(threaded.regimes[r]), mean_translation(totals.regimes[r]), 1e-12);
    EXPECT_NEAR(rms_sigmas(threaded.regimes[r]), rms_sigmas(totals.regimes[r]), 1e-12);
  }
  EXPECT_EQ(threaded.unseen_impacts, 3 * totals.unseen_impacts);
  EXPECT_NEAR(mean_ahead(threaded.impact_errors), mean_ahead(totals.impact_errors), 1e-12);
}

}  // namespace
}  // namespace fignet
