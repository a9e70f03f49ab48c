// The face- and node-pair queries (sweep and prune, then hierarchies) against all-pairs brute
// force on random multi-object scenes.
#include <gtest/gtest.h>

#include <set>
#include <tuple>

#include "fignet/geometry/triangle_distance.h"
#include "fignet/graph/contacts.h"
#include "fignet/graph/graph_builder.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

using Key = std::tuple<int, int, int, int>;

std::vector<PosedMesh> posed_current(const Scene& scene, int history) {
  std::vector<PosedMesh> posed;
  for (const SceneObject& o : scene.objects) {
    posed.push_back(
        {o.mesh, o.positions.data() + size_t(history) * o.mesh->num_vertices() * 3, o.kinematic});
  }
  return posed;
}

Triangle triangle_of(const PosedMesh& p, int face) {
  const auto v = p.vertices();
  const auto& f = p.mesh->faces().row(face);
  return {{v.row(f(0)).transpose(), v.row(f(1)).transpose(), v.row(f(2)).transpose()}};
}

std::set<Key> brute_force_faces(const std::vector<PosedMesh>& posed, double radius) {
  std::set<Key> pairs;
  for (int a = 0; a < int(posed.size()); ++a) {
    for (int b = a + 1; b < int(posed.size()); ++b) {
      if (posed[a].kinematic && posed[b].kinematic) continue;
      for (int fa = 0; fa < posed[a].mesh->num_faces(); ++fa) {
        for (int fb = 0; fb < posed[b].mesh->num_faces(); ++fb) {
          if (closest_points_triangles(triangle_of(posed[a], fa), triangle_of(posed[b], fb))
                  .distance <= radius) {
            pairs.insert({a, fa, b, fb});
          }
        }
      }
    }
  }
  return pairs;
}

// Runs the finder's own sweep and face query at `radius`; checks each pair's consistency.
std::set<Key> query_face_pairs(ContactFinder& finder, double radius) {
  std::vector<ObjectPair> candidates;
  std::vector<FacePair> found;
  finder.find_all_face_pairs(radius, candidates, found);
  std::set<Key> keys;
  for (const FacePair& p : found) {
    EXPECT_TRUE(keys.insert({p.object_a, p.face_a, p.object_b, p.face_b}).second);
    EXPECT_LE(p.distance, radius);
    EXPECT_NEAR((p.point_a - p.point_b).norm(), p.distance, 1e-12);
  }
  return keys;
}

TEST(ContactFinder, FacePairsEqualAllPairsBruteForce) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const auto fixture = testing::make_random_scene(seed, 8, 0.8);
    const auto posed = posed_current(fixture.scene, 2);
    ContactFinder finder;
    finder.update(posed, false);
    for (double radius : {0.0, 0.05, 0.1, 0.25}) {
      const std::set<Key> keys = query_face_pairs(finder, radius);
      const auto expected = brute_force_faces(posed, radius);
      EXPECT_EQ(keys, expected) << "seed " << seed << ", radius " << radius;
      if (radius == 0.1) {
        EXPECT_GT(expected.size(), 0u) << "scene has no contacts to test";
      }
    }
  }
}

TEST(ContactFinder, RefitOnMovedObjectsMatchesBruteForce) {
  auto fixture = testing::make_random_scene(9, 8, 0.8);
  ContactFinder finder;
  finder.update(posed_current(fixture.scene, 2), false);
  // Move every object by a rigid shift; the second update refits instead of rebuilding.
  for (auto& object : fixture.scene.objects) {
    object.positions.rowwise() +=
        Eigen::RowVector3d(0.1, -0.2, 0.05) * (object.properties.mass + 1);
  }
  const auto posed = posed_current(fixture.scene, 2);
  finder.update(posed, false);
  EXPECT_EQ(query_face_pairs(finder, 0.1), brute_force_faces(posed, 0.1));
}

TEST(ContactFinder, NodePairsEqualAllPairsBruteForce) {
  const auto fixture = testing::make_random_scene(3, 10, 0.8);
  const auto posed = posed_current(fixture.scene, 2);
  ContactFinder finder;
  finder.update(posed, true);
  std::vector<ObjectPair> candidates;
  std::vector<NodePair> found;
  finder.find_candidate_pairs(0.15, candidates);
  finder.find_node_pairs(candidates, 0.15, found);
  std::set<Key> keys;
  for (const NodePair& p : found) keys.insert({p.object_a, p.node_a, p.object_b, p.node_b});
  std::set<Key> expected;
  for (int a = 0; a < int(posed.size()); ++a) {
    for (int b = a + 1; b < int(posed.size()); ++b) {
      if (posed[a].kinematic && posed[b].kinematic) continue;
      for (int i = 0; i < posed[a].mesh->num_vertices(); ++i) {
        for (int j = 0; j < posed[b].mesh->num_vertices(); ++j) {
          if ((posed[a].vertices().row(i) - posed[b].vertices().row(j)).norm() <= 0.15) {
            expected.insert({a, i, b, j});
          }
        }
      }
    }
  }
  EXPECT_GT(expected.size(), 0u);
  EXPECT_EQ(keys, expected);
}

TEST(GraphBuilder, BroadphaseCandidatesGiveTheSameGraphAsTheOwnSweep) {
  const auto fixture = testing::make_random_scene(4, 8, 0.8);
  GraphBuilder builder(GraphConfig{});
  Graph own, given;
  builder.build(fixture.scene, own);
  // All object pairs, as a broadphase that found everything would report (floor included).
  std::vector<ObjectPair> all;
  const int n = int(fixture.scene.objects.size()) + 1;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) all.push_back({b, a});  // either order is accepted
  }
  builder.build_with_candidates(fixture.scene, all, given);
  ASSERT_EQ(own.face_edges.size(), given.face_edges.size());
  EXPECT_EQ(own.face_edges.receivers, given.face_edges.receivers);
  EXPECT_EQ(own.face_edges.features.matrix(), given.face_edges.features.matrix());
}

}  // namespace
}  // namespace fignet
