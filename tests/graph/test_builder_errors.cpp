// Inconsistent inputs and configs give a ConfigError that names the scene, object and field.
#include <gtest/gtest.h>

#include "fignet/error.h"
#include "fignet/graph/graph_builder.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

std::string build_error(const Scene& scene, const GraphConfig& config = {}) {
  Graph graph;
  try {
    GraphBuilder(config).build(scene, graph);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ConfigError thrown";
  return {};
}

void expect_contains(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << "'" << text << "' lacks '" << part << "'";
}

TEST(GraphBuilderErrors, HistoryLengthMismatch) {
  auto fixture = testing::make_random_scene(1, 3, 0.5, /*history=*/1);
  const std::string message = build_error(fixture.scene);  // config expects h = 2
  expect_contains(message, "scene 0, object 0");
  expect_contains(message, "positions has");
  expect_contains(message, "expected (history + 1) x vertices");
}

TEST(GraphBuilderErrors, MissingMeshNonFinitePositionAndKinematicTarget) {
  auto fixture = testing::make_random_scene(1, 3, 0.5);
  Scene no_mesh = fixture.scene;
  no_mesh.objects[1].mesh = nullptr;
  expect_contains(build_error(no_mesh), "object 1 (''): has no mesh");

  Scene nan = fixture.scene;
  nan.objects[0].positions(5, 1) = NAN;
  expect_contains(build_error(nan), "non-finite");

  Scene kinematic = fixture.scene;
  kinematic.objects[2].next_positions.resize(0, 3);  // object 2 is kinematic
  expect_contains(build_error(kinematic), "is kinematic but next_positions has 0 rows");
}

TEST(GraphBuilderErrors, BadConfigValues) {
  GraphConfig config;
  config.collision_radius = -0.1;
  EXPECT_THROW(GraphBuilder{config}, ConfigError);
  config = {};
  config.history = 0;
  try {
    GraphBuilder{config};
    FAIL();
  } catch (const ConfigError& e) {
    expect_contains(e.what(), "history = 0");
  }
  config = {};
  config.floor_half_extent = NAN;
  EXPECT_THROW(GraphBuilder{config}, ConfigError);
  config = {};
  config.distance_log_scale = -1e-3;
  try {
    GraphBuilder{config};
    FAIL();
  } catch (const ConfigError& e) {
    expect_contains(e.what(), "distance_log_scale = -0.001");
  }
  config = {};
  config.contact_motion = true;
  config.contact_motion_dead_zone = -1e-3;
  EXPECT_THROW(GraphBuilder{config}, ConfigError);
  config.contact_motion = false;
  config.contact_motion_dead_zone = 1e-3;  // would shape columns that are not there
  try {
    GraphBuilder{config};
    FAIL();
  } catch (const ConfigError& e) {
    expect_contains(e.what(), "contact_motion_dead_zone = 0.001");
    expect_contains(e.what(), "needs contact_motion");
  }
}

TEST(GraphBuilderErrors, CandidatePairOutOfRange) {
  auto fixture = testing::make_random_scene(1, 3, 0.5);
  GraphBuilder builder(GraphConfig{});
  Graph graph;
  const ObjectPair bad[] = {{0, 9}};
  EXPECT_THROW(builder.build_with_candidates(fixture.scene, bad, graph), ConfigError);
  const ObjectPair self[] = {{1, 1}};
  EXPECT_THROW(builder.build_with_candidates(fixture.scene, self, graph), ConfigError);
}

}  // namespace
}  // namespace fignet
