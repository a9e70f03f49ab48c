// Free flight outside the network (GraphConfig::omit_free_flight): the analytic motion, the
// predictor that leaves bodies without a collision edge to it, and training without them.
#include <gtest/gtest.h>

#include "fignet/error.h"
#include "fignet/rollout/free_flight.h"
#include "fignet/rollout/predictor.h"
#include "fignet/rollout/rigid_fit.h"
#include "fignet/rollout/rollout.h"
#include "fignet/train/trainer.h"
#include "model_fixtures.h"
#include "trajectory_fixtures.h"

namespace fignet {
namespace {

constexpr double kDt = 1.0 / 48.0;
const Vec3 kGravity(0, 0, -10);

ModelConfig small_model(bool omit_free_flight) {
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = 16;
  config.message_passing_steps = 2;
  config.noise_std = 0.0;
  config.graph.omit_free_flight = omit_free_flight;
  return config;
}

// A spinning cube high in the air (object 0) and a cube resting on the floor (object 1).
Trajectory flying_and_resting_cubes(int frames) {
  Trajectory trajectory;
  trajectory.time_step = kDt;
  trajectory.floor = Floor{};
  trajectory.objects.push_back(testing::ballistic_object(
      testing::small_cube(), Vec3(0, 0, 2), Vec3(1, 0, 0), Vec3(0, 4, 2), frames, kDt, kGravity));
  trajectory.objects.push_back(testing::ballistic_object(testing::small_cube(0.3), Vec3(0, 3, 0.3),
                                                         Vec3::Zero(), Vec3::Zero(), frames, kDt,
                                                         Vec3::Zero()));
  return trajectory;
}

// The same without the flying cube.
Trajectory resting_cube(int frames) {
  Trajectory trajectory = flying_and_resting_cubes(frames);
  trajectory.objects.erase(trajectory.objects.begin());
  return trajectory;
}

// Free flight at constant spin and gravity is exact: the accelerations carry the nodes, through
// the rollout's rigid fit, to the analytic pose of the next frame.
TEST(FreeFlight, AccelerationsCarryASpinningBodyToItsNextPose) {
  const Trajectory truth = flying_and_resting_cubes(8);
  Scene scene;
  scene_at_frame(truth, 4, 2, scene);
  Points accelerations(scene.objects[0].mesh->num_vertices(), 3);
  free_flight_accelerations(scene.objects[0], kGravity * kDt * kDt, accelerations);
  const SceneObject& cube = scene.objects[0];
  const Points next_nodes = accelerations + 2.0 * cube.positions_at(2) - cube.positions_at(1);
  const Pose next = fit_rigid_transform(cube.mesh->vertices(), next_nodes);
  const Pose& expected = truth.objects[0].poses[5];
  EXPECT_LT((next.position - expected.position).norm(), 1e-9);
  EXPECT_LT(next.orientation.angularDistance(expected.orientation), 1e-9);
  // Not a constant-velocity guess: the spin bends the nodes' paths.
  EXPECT_GT((accelerations.rowwise() - (kGravity * kDt * kDt).transpose()).cwiseAbs().maxCoeff(),
            1e-4);
}

// A model trained without free flight predicts the bodies in contact as if the others were not
// there (the same network on the scene without them) and moves the others in free flight.
TEST(FreeFlight, PredictorLeavesBodiesWithoutCollisionEdgesToFreeFlight) {
  const Trajectory both = flying_and_resting_cubes(8), alone = resting_cube(8);
  Scene scene, scene_alone;
  scene_at_frame(both, 4, 2, scene);
  scene_at_frame(alone, 4, 2, scene_alone);
  const auto whole = testing::random_model(scene, small_model(false));
  const auto omitting =
      std::make_shared<const Model>(small_model(true), whole->parameters(), whole->normalizers());
  PredictionOptions options{.threads = 1, .fit_masses = false};
  ModelPredictor network(whole, options), contact_only(omitting, options);
  Points all_nodes, kept_nodes, resting_alone;
  network.predict(scene, all_nodes);
  contact_only.predict(scene, kept_nodes);
  network.predict(scene_alone, resting_alone);
  const Eigen::Index flyer = scene.objects[0].mesh->num_vertices();
  ASSERT_EQ(kept_nodes.rows(), all_nodes.rows());
  // The resting cube: as the network predicts it alone (its graph is the same).
  const auto rest_rows = kept_nodes.bottomRows(resting_alone.rows());
  EXPECT_LT((rest_rows - resting_alone).cwiseAbs().maxCoeff(),
            1e-5 * (1.0 + resting_alone.cwiseAbs().maxCoeff()));
  // The flying cube: free flight, where the untrained network guesses something else.
  Points free_flight(flyer, 3);
  free_flight_accelerations(scene.objects[0], kGravity * kDt * kDt, free_flight);
  EXPECT_LT((kept_nodes.topRows(flyer) - free_flight).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT((all_nodes.topRows(flyer) - free_flight).cwiseAbs().maxCoeff(), 1e-4);
  // Any model asked to (PredictionOptions::free_flight) does the same.
  Points asked_nodes;
  options.free_flight = true;
  ModelPredictor asked(whole, options);
  asked.predict(scene, asked_nodes);
  EXPECT_EQ(asked_nodes, kept_nodes);
  // Its graph holds the resting cube and the floor only.
  EXPECT_EQ(contact_only.last_graph().num_objects(), 2);
  // With the caller's candidate pairs (the floor is object 2), the same.
  Points with_candidates;
  const std::vector<ObjectPair> pairs = {{0, 1}, {0, 2}, {1, 2}};
  contact_only.predict_with_candidates(scene, pairs, with_candidates);
  EXPECT_LT((with_candidates - kept_nodes).cwiseAbs().maxCoeff(), 1e-6);
  // A scene of bodies in the air alone needs no network.
  Scene flying = scene;
  flying.objects.pop_back();
  Points flying_nodes;
  contact_only.predict(flying, flying_nodes);
  EXPECT_LT((flying_nodes - free_flight).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(contact_only.last_graph().num_mesh_nodes(),
            contact_only.last_graph().object_first_node.back());
  EXPECT_EQ(contact_only.last_graph().num_objects(), 1);  // the floor
}

// A caller that has searched the scene already (the Bullet world, to choose the bodies it passes)
// hands the search on: the same accelerations to the bit as the predictor's own search gives, for
// a model that omits free flight, one asked to, one that sees every body, and with turns.
TEST(FreeFlight, PredictorReusesTheCallersSearch) {
  const Trajectory both = flying_and_resting_cubes(8);
  Scene scene;
  scene_at_frame(both, 4, 2, scene);
  // A kinematic body near the flying cube but out of its reach: a candidate without an edge.
  scene.objects.push_back(scene.objects[1]);
  SceneObject& post = scene.objects.back();
  const Eigen::RowVector3d lift(0.5, 0, 2.0);
  post.kinematic = true;
  post.properties.mass = 0.0;
  post.positions.rowwise() += lift;
  post.centers.rowwise() += lift;
  post.next_positions = post.positions_at(post.num_steps() - 1);
  post.next_center = post.centers.bottomRows(1).transpose();
  const auto whole = testing::random_model(scene, small_model(false));
  const auto omitting =
      std::make_shared<const Model>(small_model(true), whole->parameters(), whole->normalizers());
  // The floor is object 3.
  const std::vector<ObjectPair> pairs = {{0, 1}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  GraphBuilder search(whole->config().graph);
  std::vector<char> interacting;
  SceneContacts contacts;
  search.find_interacting_objects(scene, pairs, interacting, &contacts);
  ASSERT_EQ(interacting, (std::vector<char>{0, 1, 0, 1}));
  struct Case {
    const char* name;
    std::shared_ptr<const Model> model;
    PredictionOptions options;
  };
  const Case cases[] = {
      {"omitting", omitting, {.threads = 1}},
      {"asked to", whole, {.threads = 1, .free_flight = true}},
      {"every body", whole, {.threads = 1}},
      {"two turns", omitting, {.threads = 1, .turns = 2}},
      {"every body, two turns", whole, {.threads = 1, .turns = 2}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    ModelPredictor own(c.model, c.options), given(c.model, c.options);
    Points searched_here, searched_before;
    own.predict_with_candidates(scene, pairs, searched_here);
    given.predict_with_search(scene, pairs, interacting, contacts, searched_before);
    EXPECT_EQ(searched_before, searched_here);
    EXPECT_EQ(given.last_graph().face_edges.size(), own.last_graph().face_edges.size());
    EXPECT_EQ(given.last_graph().num_objects(), own.last_graph().num_objects());
  }
  // A search that is not of this scene is refused, naming what does not match.
  ModelPredictor predictor(omitting, {.threads = 1});
  auto error_of = [&](std::span<const char> flags) -> std::string {
    Points accelerations;
    try {
      predictor.predict_with_search(scene, pairs, flags, contacts, accelerations);
    } catch (const ConfigError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no ConfigError thrown";
    return {};
  };
  const std::vector<char> too_few(2, 1);
  EXPECT_NE(error_of(too_few).find("2 interaction flags for a scene of 3 objects"),
            std::string::npos);
  std::vector<char> resting_unflagged = interacting;
  resting_unflagged[1] = 0;  // its face pairs with the floor now join an object without an edge
  ASSERT_FALSE(contacts.faces.empty());
  EXPECT_NE(error_of(resting_unflagged).find("face pair 0 joins objects 1 and 3"),
            std::string::npos);
}

// Training without free flight is training on the bodies in contact alone: the same graphs,
// loss and parameters as a run on the data without the flying cube; a pushed scene's flying
// cube moves in free flight, not as the network says.
TEST(FreeFlight, TrainingLeavesBodiesWithoutCollisionEdgesOut) {
  const std::vector<Trajectory> both = {flying_and_resting_cubes(10)};
  const std::vector<Trajectory> alone = {resting_cube(10)};
  TrainerConfig trainer_config;
  trainer_config.batch_size = 2;
  Trainer omitting(small_model(true), trainer_config, both);
  Trainer reference(small_model(false), trainer_config, alone);
  const std::vector<SampleRef> samples = {{0, 3}, {0, 6}};
  omitting.step_on(samples, 3);
  reference.step_on(samples, 3);
  EXPECT_EQ(omitting.batch_graph().num_mesh_nodes(), reference.batch_graph().num_mesh_nodes());
  EXPECT_EQ(omitting.batch_graph().num_objects(), 4);  // the resting cube and the floor, twice
  EXPECT_EQ(omitting.batch_graph().face_edges.size(), reference.batch_graph().face_edges.size());
  EXPECT_NEAR(omitting.evaluate_loss(samples), reference.evaluate_loss(samples), 1e-6);
  for (size_t i = 0; i < omitting.parameters().size(); ++i) {
    ASSERT_NEAR(omitting.parameters()[i], reference.parameters()[i], 1e-6) << i;
  }
  // Pushed: the flying cube's current pose is its free flight from the frame before, which is
  // the truth; the resting cube's is the network's guess.
  trainer_config.pushforward_fraction = 1.0f;
  Trainer pushing(small_model(true), trainer_config, both);
  pushing.step_on(samples, 3);
  ASSERT_EQ(pushing.batch_pushed(), (std::vector<std::uint8_t>{1, 1}));
  for (size_t b = 0; b < samples.size(); ++b) {
    const Scene& scene = pushing.batch_scenes()[b];
    const Pose flyer =
        fit_rigid_transform(scene.objects[0].mesh->vertices(), scene.objects[0].positions_at(2));
    const Pose& truth = both[0].objects[0].poses[samples[b].frame];
    EXPECT_LT((flyer.position - truth.position).norm(), 1e-9) << b;
    EXPECT_LT(flyer.orientation.angularDistance(truth.orientation), 1e-9) << b;
  }
}

}  // namespace
}  // namespace fignet
