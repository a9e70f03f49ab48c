#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "fignet/bullet/dataset_generator.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"
#include "fignet/graph/contacts.h"
#include "fignet/train/training_batch.h"

namespace fignet::bullet {
namespace {

GenerateOptions small_options(int threads) {
  GenerateOptions options;
  options.count = 6;
  options.seed = 11;
  options.scene.frames = 48;
  options.threads = threads;
  return options;
}

void expect_identical(const std::vector<Trajectory>& a, const std::vector<Trajectory>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].objects.size(), b[i].objects.size());
    for (size_t o = 0; o < a[i].objects.size(); ++o) {
      for (int f = 0; f < a[i].num_frames(); ++f) {
        ASSERT_EQ(a[i].objects[o].poses[f].position, b[i].objects[o].poses[f].position);
        ASSERT_EQ(a[i].objects[o].poses[f].orientation.coeffs(),
                  b[i].objects[o].poses[f].orientation.coeffs());
      }
    }
  }
}

// How many face pairs of different bodies lie within `radius` of each other.
size_t face_pairs_within(const std::vector<std::pair<const TriangleMesh*, Pose>>& bodies,
                         double radius) {
  std::vector<Points> posed;
  for (const auto& [mesh, pose] : bodies) posed.push_back(posed_vertices(*mesh, pose));
  std::vector<PosedMesh> meshes;
  for (size_t i = 0; i < bodies.size(); ++i)
    meshes.push_back({bodies[i].first, posed[i].data(), false});
  ContactFinder finder;
  finder.update(meshes, false);
  std::vector<ObjectPair> pairs;
  std::vector<FacePair> close;
  finder.find_all_face_pairs(radius, pairs, close);
  return close.size();
}

TEST(Generator, SameSeedSameTrajectoriesWhateverTheThreadsAndShards) {
  const auto one = generate_dataset(small_options(1));
  expect_identical(one, generate_dataset(small_options(2)));
  GenerateOptions first = small_options(2), second = small_options(2);
  first.shards = second.shards = 2;
  second.shard = 1;
  auto sharded = generate_dataset(first);
  for (auto& t : generate_dataset(second)) sharded.push_back(std::move(t));
  expect_identical(one, sharded);
  GenerateOptions other = small_options(2);
  other.seed = 12;
  EXPECT_NE(generate_dataset(other)[0].objects[0].poses[0].position,
            one[0].objects[0].poses[0].position);
}

TEST(Generator, MoviAScenesFollowKubricParameters) {
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    const SceneSpec spec = sample_movi_scene({}, trajectory_seed(5, seed));
    ASSERT_GE(spec.bodies.size(), 1u);
    EXPECT_LE(spec.bodies.size(), 10u);
    EXPECT_EQ(spec.floor->properties.friction, 0.3);
    EXPECT_EQ(spec.floor->properties.restitution, 0.5);
    for (const BodySpec& body : spec.bodies) {
      // Mass = density × mesh volume; metal 2.7 or rubber 1.1 with their friction.
      const double volume = compute_mass_properties(*body.mesh).volume;
      const double density = body.properties.mass / volume;
      EXPECT_TRUE(std::abs(density - 2.7) < 1e-9 || std::abs(density - 1.1) < 1e-9) << density;
      EXPECT_EQ(body.properties.friction, density > 2 ? 0.4 : 0.8);
      EXPECT_GE(body.pose.position.z(), 1.0);
      EXPECT_LE(body.pose.position.cwiseAbs().maxCoeff(), 5.0);
      EXPECT_EQ(body.linear_velocity.z(), 0.0);
      // Tossed toward the centre: velocity = uniform(±4) − (x, y).
      EXPECT_LE(
          (body.linear_velocity.head<2>() + body.pose.position.head<2>()).cwiseAbs().maxCoeff(),
          4.0);
      if (body.mesh->name() == "cube") {
        const double side = 2 * body.mesh->vertices().col(0).maxCoeff();
        EXPECT_TRUE(std::abs(side - 1.4) < 1e-9 || std::abs(side - 2.8) < 1e-9) << side;
        EXPECT_NEAR(volume, side * side * side, 1e-9);
      }
    }
  }
}

TEST(Generator, ScenesStartWithoutOverlapAndStayAboveTheFloor) {
  GenerateOptions options = small_options(2);
  options.count = 10;
  options.scene.frames = 96;
  for (const Trajectory& t : generate_dataset(options)) {
    // Frame 0: no two objects' surfaces touch (the bounding-sphere spawn test is conservative).
    std::vector<std::pair<const TriangleMesh*, Pose>> bodies;
    for (const auto& object : t.objects) bodies.emplace_back(object.mesh.get(), object.poses[0]);
    EXPECT_EQ(face_pairs_within(bodies, 0.0), 0u) << "seed " << t.seed;
    // Every frame: every vertex above the floor, up to Bullet's transient contact penetration,
    // which is at most one step of travel at impact: a 5 m drop lands at 10 m/s, 10/240 = 4.2 cm.
    for (const auto& object : t.objects) {
      for (const Pose& pose : object.poses) {
        EXPECT_GE(posed_vertices(*object.mesh, pose).col(2).minCoeff(), -0.05) << "seed " << t.seed;
      }
    }
  }
}

// Still bodies in the air (the trainer's still_air_fraction) are taught to fall freely, so they
// must start clear of where resting bodies lie: bodies at rest on the floor in generated data have
// their lowest vertex at Bullet's collision margin, at least two steps of free fall below the
// smallest still-air gap.
TEST(Generator, BodiesRestingOnTheFloorLieBelowTheSmallestStillAirGap) {
  GenerateOptions options = small_options(2);
  options.count = 10;
  options.scene.frames = 192;  // long enough for most bodies to come to rest
  int resting = 0;
  for (const Trajectory& t : generate_dataset(options)) {
    const double fall = t.gravity.norm() * t.time_step * t.time_step;
    // The bodies the trainer weighs as resting (rest_loss_weight), at the second-last frame.
    const int frame = t.num_frames() - 2;
    const auto at_rest = resting_objects(t, frame, kRestSpeed * t.time_step);
    for (size_t o = 0; o < t.objects.size(); ++o) {
      if (!at_rest[o]) continue;
      const TrajectoryObject& object = t.objects[o];
      const double lowest =
          posed_vertices(*object.mesh, object.poses[frame]).col(2).minCoeff() - t.floor->height;
      if (lowest > 0.05) continue;  // resting on another body
      ++resting;
      EXPECT_NEAR(lowest, SceneSpec{}.collision_margin, 1e-3) << "seed " << t.seed;
      EXPECT_LE(lowest, kStillAirGaps[0] - 2 * fall) << "seed " << t.seed;
    }
  }
  EXPECT_GE(resting, 3);
}

TEST(Generator, PusherFollowsItsScriptedPathExactly) {
  GenerateOptions options;
  options.scene.preset = "pushing";
  options.count = 10;
  options.seed = 4;
  int moved = 0;
  for (const Trajectory& t : generate_dataset(options)) {
    ASSERT_EQ(t.num_frames(), 42);
    EXPECT_NEAR(t.time_step, 3.0 / 250.0, 1e-15);
    const SceneSpec spec = sample_pushing_scene(options.scene, t.seed);
    const TrajectoryObject& pusher = t.objects[1];
    ASSERT_TRUE(pusher.kinematic);
    EXPECT_EQ(pusher.properties.mass, 0.0);
    for (int f = 0; f < t.num_frames(); ++f) {
      const Vec3 scripted =
          spec.bodies[1].pose.position + spec.bodies[1].linear_velocity * f * t.time_step;
      EXPECT_LT((pusher.poses[f].position - scripted).norm(), 1e-6)
          << "frame " << f;  // float32 Bullet
    }
    // The object starts at rest on the plane and ends up pushed in most scenes.
    const TrajectoryObject& object = t.objects[0];
    EXPECT_FALSE(object.kinematic);
    moved += (object.poses.back().position - object.poses.front().position).norm() > 1e-3;
  }
  EXPECT_GE(moved, 5);
}

TEST(Generator, MoviBUsesEveryShapeAtContinuousScales) {
  std::set<std::string> names;
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    MoviOptions options;
    options.preset = "movi-b";
    for (const BodySpec& body : sample_scene(options, trajectory_seed(9, seed)).bodies) {
      names.insert(body.mesh->name());
      const bool convex = body.convex_parts.empty();
      const std::string& name = body.mesh->name();
      EXPECT_EQ(convex,
                name != "torus" && name != "torus_knot" && name != "gear" && name != "sponge")
          << name;
    }
  }
  EXPECT_EQ(names.size(), movi_shape_names().size());
}

MoviOptions stacks_only(int stacks) {
  MoviOptions options;
  options.stacks = stacks;
  options.min_objects = options.max_objects = 0;
  return options;
}

double half_width(const BodySpec& body) {
  return body.mesh->vertices().col(0).maxCoeff();
}
double lowest(const BodySpec& body) {
  return posed_vertices(*body.mesh, body.pose).col(2).minCoeff();
}
double highest(const BodySpec& body) {
  return posed_vertices(*body.mesh, body.pose).col(2).maxCoeff();
}

// Every stacked body is an upright cube or cylinder at rest, lying at the collision margin on the
// floor or on one body below it, nearly centred on it; returns the levels seen over 20 seeds.
std::set<int> stack_levels_seen(const MoviOptions& options) {
  std::set<int> heights;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    const SceneSpec spec = sample_movi_scene(options, trajectory_seed(3, seed));
    const double margin = spec.collision_margin;
    std::vector<int> level(spec.bodies.size(), 0);
    for (size_t i = 0; i < spec.bodies.size(); ++i) {
      const BodySpec& body = spec.bodies[i];
      const std::string& name = body.mesh->name();
      EXPECT_TRUE(name == "cube" || name == "cylinder") << name;
      EXPECT_EQ(body.linear_velocity, Vec3::Zero());
      EXPECT_EQ(body.angular_velocity, Vec3::Zero());
      EXPECT_LT((body.pose.orientation * Vec3::UnitZ() - Vec3::UnitZ()).norm(), 1e-12);
      if (std::abs(lowest(body) - spec.floor->height - margin) < 1e-9) {
        level[i] = 1;
      } else {
        int supports = 0;
        for (size_t j = 0; j < i; ++j) {
          const BodySpec& below = spec.bodies[j];
          if (std::abs(lowest(body) - highest(below) - margin) > 1e-9) continue;
          const double off_axis = (body.pose.position - below.pose.position).head<2>().norm();
          if (off_axis > 0.1 * std::min(half_width(body), half_width(below)) + 1e-9) continue;
          ++supports;
          level[i] = level[j] + 1;
        }
        EXPECT_EQ(supports, 1) << "seed " << seed << " body " << i;
      }
      heights.insert(level[i]);
    }
  }
  return heights;
}

TEST(Generator, StacksStandStillOnTheFloorOrSquarelyOnOneBody) {
  EXPECT_EQ(stack_levels_seen(stacks_only(3)), (std::set<int>{1, 2, 3}));
}

// Stacks of 4 or 5: every level from the floor up is there, and none above the range.
TEST(Generator, TallerStacksHaveTheLevelsAsked) {
  MoviOptions options = stacks_only(2);
  options.min_stack_levels = 4;
  options.max_stack_levels = 5;
  EXPECT_EQ(stack_levels_seen(options), (std::set<int>{1, 2, 3, 4, 5}));
}

// The data must show stacks standing: in Bullet every body of `scene`'s stacks stays within
// `drift` and 0.02 rad of where it started over a whole trajectory; returns how many bodies.
int bodies_that_stand(const MoviOptions& scene, int count, std::uint64_t seed, double drift) {
  GenerateOptions options;
  options.scene = scene;
  options.count = count;
  options.seed = seed;
  options.threads = 2;
  int bodies = 0;
  for (const Trajectory& t : generate_dataset(options)) {
    for (const TrajectoryObject& object : t.objects) {
      ++bodies;
      const Pose& first = object.poses.front();
      const Pose& last = object.poses.back();
      EXPECT_LT((last.position - first.position).norm(), drift) << "seed " << t.seed;
      EXPECT_LT(last.orientation.angularDistance(first.orientation), 0.02) << "seed " << t.seed;
    }
  }
  return bodies;
}

TEST(Generator, StacksStandInBullet) {
  EXPECT_GE(bodies_that_stand(stacks_only(3), 4, 8, 0.02), 12);
}

// Stacks of five settle a little more (five contacts' worth), up to 2.4 cm at the top.
TEST(Generator, StacksOfFiveStandInBullet) {
  MoviOptions scene = stacks_only(2);
  scene.min_stack_levels = scene.max_stack_levels = 5;
  EXPECT_GE(bodies_that_stand(scene, 3, 9, 0.03), 20);
}

// Counts, over 20 seeds, the stacks and the spheres on them. Every sphere lies still on a facet
// (one face's normal points straight down) at the collision margin over the top of exactly one
// stack, nearly centred on it, and nothing lies on a sphere.
std::pair<int, int> stacks_and_spheres_seen(const MoviOptions& options) {
  int stacks = 0, spheres = 0;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    const SceneSpec spec = sample_movi_scene(options, trajectory_seed(6, seed));
    const double margin = spec.collision_margin;
    for (const BodySpec& body : spec.bodies) {
      stacks += std::abs(lowest(body) - spec.floor->height - margin) < 1e-9;
      if (body.mesh->name() != "sphere") continue;
      ++spheres;
      EXPECT_EQ(body.linear_velocity, Vec3::Zero());
      EXPECT_EQ(body.angular_velocity, Vec3::Zero());
      const Points normals =
          body.mesh->face_normals() * body.pose.orientation.toRotationMatrix().transpose();
      EXPECT_LT((normals.col(2).array() + 1.0).abs().minCoeff(), 1e-9) << "seed " << seed;
      const double radius = body.mesh->vertices().rowwise().norm().maxCoeff();
      int supports = 0;
      for (const BodySpec& other : spec.bodies) {
        // Stacks of equal levels have tops at equal heights: only a body under or over the
        // sphere counts.
        const double off_axis = (body.pose.position - other.pose.position).head<2>().norm();
        if (&other == &body || off_axis > radius + half_width(other)) continue;
        EXPECT_GT(std::abs(lowest(other) - highest(body) - margin), 1e-6)
            << "a body on a sphere, seed " << seed;
        if (std::abs(lowest(body) - highest(other) - margin) > 1e-9) continue;
        EXPECT_LE(off_axis, 0.1 * std::min(radius, half_width(other)) + 1e-9) << "seed " << seed;
        ++supports;
      }
      EXPECT_EQ(supports, 1) << "seed " << seed;
    }
  }
  return {stacks, spheres};
}

TEST(Generator, SphereToppedStacksRestASphereOnAFacetOfTheTop) {
  MoviOptions options = stacks_only(2);
  options.sphere_topped_stacks = 1.0;
  const auto [stacks, spheres] = stacks_and_spheres_seen(options);
  EXPECT_EQ(spheres, stacks);
  EXPECT_GE(stacks, 30);
  // A share: some stacks topped, some not; none without the option.
  options.sphere_topped_stacks = 0.5;
  const auto [half_stacks, half_spheres] = stacks_and_spheres_seen(options);
  EXPECT_GT(half_spheres, half_stacks / 4);
  EXPECT_LT(half_spheres, 3 * half_stacks / 4);
  options.sphere_topped_stacks = 0.0;
  EXPECT_EQ(stacks_and_spheres_seen(options).second, 0);
}

// The spheres stay where they lie, as the stacks under them do.
TEST(Generator, SphereToppedStacksStandInBullet) {
  MoviOptions scene = stacks_only(3);
  scene.sphere_topped_stacks = 1.0;
  EXPECT_GE(bodies_that_stand(scene, 4, 8, 0.02), 16);
}

// Tossed objects spawn clear of the stacks.
TEST(Generator, TossedObjectsSpawnClearOfTheStacks) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    MoviOptions options;
    options.stacks = 2;
    const SceneSpec spec = sample_movi_scene(options, trajectory_seed(4, seed));
    std::vector<std::pair<const TriangleMesh*, Pose>> bodies;
    for (const BodySpec& body : spec.bodies) bodies.emplace_back(body.mesh.get(), body.pose);
    // Stacked bodies lie at the margin on one another; nothing else comes that close.
    EXPECT_EQ(face_pairs_within(bodies, spec.collision_margin / 2), 0u) << "seed " << seed;
    int tossed = 0;
    for (const BodySpec& body : spec.bodies) tossed += body.linear_velocity != Vec3::Zero();
    EXPECT_GE(tossed, 1) << "seed " << seed;
  }
}

MoviOptions piles_only(int piles) {
  MoviOptions options;
  options.piles = piles;
  options.min_pile_objects = 5;
  options.max_pile_objects = 6;
  options.min_objects = options.max_objects = 0;
  return options;
}

// Piles start settled: every body still and none below the floor; in some scenes bodies lie on
// others (their lowest point well above the floor). Through a whole trajectory in Bullet most
// bodies stay where they lay; round ones may roll off (Bullet has no rolling friction here), and
// what lay on them with them. A column dropped without settling would fall metres instead.
TEST(Generator, PilesStartSettledWithBodiesOnOneAnother) {
  GenerateOptions options;
  options.scene = piles_only(2);
  options.count = 6;
  options.seed = 11;
  options.threads = 2;
  int scenes_with_a_body_on_another = 0, bodies = 0, bodies_still = 0;
  for (std::uint64_t i = 0; i < 6; ++i) {
    const SceneSpec spec = sample_movi_scene(options.scene, trajectory_seed(options.seed, i));
    EXPECT_GE(spec.bodies.size(), 10u) << "scene " << i;  // a pile left out would leave fewer
    bool on_another = false;
    for (const BodySpec& body : spec.bodies) {
      EXPECT_EQ(body.linear_velocity, Vec3::Zero());
      EXPECT_EQ(body.angular_velocity, Vec3::Zero());
      EXPECT_GT(lowest(body), spec.floor->height - 0.01);
      on_another = on_another || lowest(body) > spec.floor->height + 0.05;
    }
    scenes_with_a_body_on_another += on_another;
  }
  EXPECT_GE(scenes_with_a_body_on_another, 2);
  for (const Trajectory& t : generate_dataset(options)) {
    for (const TrajectoryObject& object : t.objects) {
      ++bodies;
      bodies_still += (object.poses.back().position - object.poses.front().position).norm() < 0.02;
      EXPECT_LT((object.poses.back().position - object.poses.front().position).norm(), 2.0);
    }
  }
  EXPECT_GE(bodies_still, bodies / 2) << bodies_still << " of " << bodies;
}

// Tossed objects spawn clear of the piles: their bounding spheres meet no pile body's.
TEST(Generator, TossedObjectsSpawnClearOfThePiles) {
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    MoviOptions options;
    options.piles = 1;
    const SceneSpec spec = sample_movi_scene(options, trajectory_seed(5, seed));
    int tossed = 0;
    for (const BodySpec& body : spec.bodies) {
      if (body.linear_velocity == Vec3::Zero()) continue;
      ++tossed;
      const double radius = body.mesh->vertices().rowwise().norm().maxCoeff();
      for (const BodySpec& pile : spec.bodies) {
        if (pile.linear_velocity != Vec3::Zero()) continue;
        const double pile_radius = pile.mesh->vertices().rowwise().norm().maxCoeff();
        EXPECT_GT((body.pose.position - pile.pose.position).norm(), radius + pile_radius)
            << "seed " << seed;
      }
    }
    EXPECT_GE(tossed, 1) << "seed " << seed;
  }
}

TEST(Generator, DatasetInfoRecordsEveryOptionThatShapesTheScenes) {
  GenerateOptions options = small_options(1);
  options.scene.preset = "movi-b";
  options.seed = 19;
  options.scene.stacks = 2;
  options.scene.min_stack_levels = 4;
  options.scene.max_stack_levels = 6;
  options.scene.piles = 3;
  options.scene.min_pile_objects = 2;
  options.scene.max_pile_objects = 9;
  options.scene.sphere_topped_stacks = 0.25;
  EXPECT_EQ(dataset_info(options, "9.8.7"),
            (DatasetInfo{"movi-b", "9.8.7", 19, 2, 4, 6, 3, 2, 9, 0.25}));
}

TEST(Generator, BadOptionsAreConfigErrors) {
  GenerateOptions options = small_options(1);
  options.shard = 2;
  options.shards = 2;
  EXPECT_THROW(generate_dataset(options), ConfigError);
  options = small_options(1);
  options.scene.preset = "movi-z";
  EXPECT_THROW(generate_dataset(options), ConfigError);
  options = small_options(1);
  options.scene.min_objects = 5;
  options.scene.max_objects = 4;
  EXPECT_THROW(generate_dataset(options), ConfigError);
  options = small_options(1);
  options.scene.min_objects = 0;  // a scene without any body
  EXPECT_THROW(generate_dataset(options), ConfigError);
  options.scene.stacks = -1;
  EXPECT_THROW(generate_dataset(options), ConfigError);
  // Ranges of stack levels and of pile objects: empty, below 1, above the most.
  auto expect_bad_ranges = [](int most, auto set) {
    for (auto [fewest, largest] : {std::pair(0, 3), std::pair(4, 3), std::pair(1, most + 1)}) {
      GenerateOptions bad = small_options(1);
      set(bad.scene, fewest, largest);
      EXPECT_THROW(generate_dataset(bad), ConfigError) << fewest << ".." << largest;
    }
  };
  expect_bad_ranges(kMaxStackLevels, [](MoviOptions& scene, int fewest, int most) {
    scene.stacks = 1;
    scene.min_stack_levels = fewest;
    scene.max_stack_levels = most;
  });
  expect_bad_ranges(kMaxPileObjects, [](MoviOptions& scene, int fewest, int most) {
    scene.piles = 1;
    scene.min_pile_objects = fewest;
    scene.max_pile_objects = most;
  });
  for (const char* preset : {"movi-c", "pushing"}) {
    options = small_options(1);
    options.scene.preset = preset;
    options.scene.stacks = 1;
    EXPECT_THROW(generate_dataset(options), ConfigError) << preset;
    options.scene.stacks = 0;
    options.scene.piles = 1;
    EXPECT_THROW(generate_dataset(options), ConfigError) << preset;
  }
  options = small_options(1);
  options.scene.piles = -1;
  EXPECT_THROW(generate_dataset(options), ConfigError);
  // A share of stacks outside 0-1, or spheres without stacks to top.
  for (double share : {-0.1, 1.5, std::nan("")}) {
    options = small_options(1);
    options.scene.stacks = 1;
    options.scene.sphere_topped_stacks = share;
    EXPECT_THROW(generate_dataset(options), ConfigError) << share;
  }
  options = small_options(1);
  options.scene.sphere_topped_stacks = 0.5;
  EXPECT_THROW(generate_dataset(options), ConfigError);
}

}  // namespace
}  // namespace fignet::bullet
