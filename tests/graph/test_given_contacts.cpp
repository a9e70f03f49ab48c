// GraphBuilder::build_with_contacts: a scene built from the collision pairs a search of it found
// equals the scene built with its own search, field by field; FreeFlightSplit's renumbered pairs
// build its kept scene as a search of that scene would; bad pairs are rejected by name.
#include <gtest/gtest.h>

#include "../error_text.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/rollout/free_flight.h"
#include "graph_compare.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

using testing::error_of;
using testing::expect_same_graph;

struct Variant {
  CollisionEdges collisions;
  FloorModel floor;
};

class GivenContacts : public ::testing::TestWithParam<Variant> {
 protected:
  GivenContacts() {
    config.collisions = GetParam().collisions;
    config.floor = GetParam().floor;
    config.collision_radius = 0.3;
  }

  // Random shapes touching each other and the floor, and a copy of the first one 5 m above the
  // rest, which touches nothing.
  testing::RandomScene scene_with_a_body_in_the_air(unsigned seed) const {
    testing::RandomScene fixture = testing::make_random_scene(seed, 6, 0.4);
    SceneObject flying = fixture.scene.objects[0];
    flying.positions.col(2).array() += 5.0;
    flying.centers.col(2).array() += 5.0;
    fixture.scene.objects.insert(fixture.scene.objects.begin() + 2, flying);
    return fixture;
  }

  GraphConfig config;
};

TEST_P(GivenContacts, ASearchsOwnPairsBuildTheSameGraph) {
  const testing::RandomScene fixture = testing::make_random_scene(3, 6, 0.4);
  GraphBuilder builder(config);
  std::vector<char> interacting;
  SceneContacts found;
  builder.find_interacting_objects(fixture.scene, interacting, &found);
  ASSERT_FALSE(found.faces.empty() && found.nodes.empty());
  Graph searched, given;
  builder.build(fixture.scene, searched);
  const std::vector<FacePair> searched_pairs(builder.face_pairs().begin(),
                                             builder.face_pairs().end());
  builder.build_with_contacts(std::span(&fixture.scene, 1), std::span(&found, 1), given);
  expect_same_graph(given, searched);
  ASSERT_EQ(builder.face_pairs().size(), searched_pairs.size());
  for (size_t p = 0; p < searched_pairs.size(); ++p) {
    EXPECT_EQ(builder.face_pairs()[p].object_a, searched_pairs[p].object_a);
    EXPECT_EQ(builder.face_pairs()[p].face_b, searched_pairs[p].face_b);
  }
  // The pairs are taken as given, not searched: none given, no collision edges.
  const SceneContacts none;
  builder.build_with_contacts(std::span(&fixture.scene, 1), std::span(&none, 1), given);
  EXPECT_EQ(given.face_edges.size() + given.world_edges.size(), 0);
  EXPECT_EQ(given.mesh_nodes.matrix(), searched.mesh_nodes.matrix());
}

// The split leaves out the body in the air; its renumbered pairs build the kept scene as a search
// of the kept scene does, for two scenes in one graph too.
TEST_P(GivenContacts, SplitPairsBuildTheKeptSceneAsItsOwnSearch) {
  const testing::RandomScene first = scene_with_a_body_in_the_air(5),
                             second = scene_with_a_body_in_the_air(6);
  GraphBuilder builder(config);
  FreeFlightSplit split;
  std::vector<Scene> kept(2);
  std::vector<SceneContacts> contacts(2);
  split.split(builder, first.scene, nullptr, kept[0], contacts[0]);
  EXPECT_FALSE(split.keeps(2));
  EXPECT_LT(kept[0].objects.size(), first.scene.objects.size());
  split.split(builder, second.scene, nullptr, kept[1], contacts[1]);
  EXPECT_FALSE(split.keeps(2));

  Graph searched, given;
  builder.build(kept, searched);
  builder.build_with_contacts(kept, contacts, given);
  ASSERT_GT(searched.face_edges.size() + searched.world_edges.size(), 0);
  expect_same_graph(given, searched);
}

// With the caller's candidate pairs (a physics engine's broadphase) as well.
TEST_P(GivenContacts, SplitPairsFromCandidatesBuildTheKeptScene) {
  const testing::RandomScene fixture = scene_with_a_body_in_the_air(8);
  const int objects = static_cast<int>(fixture.scene.objects.size());
  std::vector<ObjectPair> candidates;
  for (int a = 0; a < objects; ++a) {
    for (int b = a + 1; b < objects; ++b) candidates.push_back({a, b});
  }
  GraphBuilder builder(config);
  FreeFlightSplit split;
  Scene kept;
  SceneContacts contacts;
  const std::span<const ObjectPair> all(candidates);
  split.split(builder, fixture.scene, &all, kept, contacts);
  EXPECT_FALSE(split.keeps(2));
  Graph searched, given;
  builder.build_with_candidates(kept, split.kept_candidates(), searched);
  builder.build_with_contacts(std::span(&kept, 1), std::span(&contacts, 1), given);
  expect_same_graph(given, searched);
}

INSTANTIATE_TEST_SUITE_P(CollisionsAndFloors, GivenContacts,
                         ::testing::Values(Variant{CollisionEdges::kFaceFace, FloorModel::kMesh},
                                           Variant{CollisionEdges::kFaceFace,
                                                   FloorModel::kImplicit},
                                           Variant{CollisionEdges::kNodeNode, FloorModel::kMesh}));

TEST(GivenContactsErrors, CountsObjectsFacesAndNodesAreChecked) {
  const testing::RandomScene fixture = testing::make_random_scene(3, 3, 0.4);
  GraphBuilder builder(GraphConfig{});
  Graph graph;
  const std::span<const Scene> one(&fixture.scene, 1);
  EXPECT_NE(error_of([&] {
              builder.build_with_contacts(one, {}, graph);
            }).find("1 scenes but contacts for 0"),
            std::string::npos);

  SceneContacts contacts;
  contacts.faces.push_back({0, 0, 7, 0, Vec3::Zero(), Vec3::Zero(), 0.0});
  EXPECT_NE(error_of([&] {
              builder.build_with_contacts(one, std::span(&contacts, 1), graph);
            }).find("scene 0: given face pair 0 joins objects 0 and 7"),
            std::string::npos);

  const int faces = fixture.scene.objects[1].mesh->num_faces();
  contacts.faces = {{0, 0, 1, faces, Vec3::Zero(), Vec3::Zero(), 0.0}};
  EXPECT_NE(error_of([&] {
              builder.build_with_contacts(one, std::span(&contacts, 1), graph);
            }).find("names faces 0 of object 0 and " + std::to_string(faces) + " of object 1"),
            std::string::npos);

  contacts.faces.clear();
  contacts.nodes = {{2, 0, 1, 0, 0.0}};
  EXPECT_NE(error_of([&] {
              builder.build_with_contacts(one, std::span(&contacts, 1), graph);
            }).find("given node pair 0 joins objects 2 and 1"),
            std::string::npos);
}

}  // namespace
}  // namespace fignet
