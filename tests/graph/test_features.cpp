// Feature values of a two-tetrahedra scene, derived by hand (see the comments), and batching.
//
// Both objects share the tetrahedron (0,0,0),(1,0,0),(0,1,0),(0,0,1) expressed in its
// centre-of-mass frame (shifted by -1/4 on each axis). A is dynamic and translates along x: centres
// 0, 0.01, 0.03 at t-2, t-1, t. B is kinematic and static until it moves +0.001 in z at t+1; its
// apex (vertex 3) points up at A's bottom face (z = -1/4 in A's frame), 0.05 m below the point
// (0.1, 0.05) of it. With d_c = 0.1 exactly three face pairs are within range: A's bottom face with
// each of the three faces of B around its apex.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "fignet/graph/graph_builder.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

TriangleMesh centered_tetrahedron() {
  Points v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  v.array() -= 0.25;
  Triangles f(4, 3);
  f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return TriangleMesh("tetrahedron", v, f);
}

class TwoTetrahedra : public ::testing::Test {
 protected:
  void SetUp() override {
    SceneObject a;
    a.mesh = &mesh_;
    set_pose_history(a, std::vector<Pose>{{Vec3(0, 0, 0)}, {Vec3(0.01, 0, 0)}, {Vec3(0.03, 0, 0)}});
    a.properties = {2.0, 0.4, 0.3};
    const Vec3 apex = Vec3(0.03, 0, 0) + Vec3(0.1, 0.05, -0.25 - 0.05);
    const Vec3 center_b = apex - Vec3(-0.25, -0.25, 0.75);
    SceneObject b;
    b.mesh = &mesh_;
    b.kinematic = true;
    b.properties = {0.0, 0.8, 0.7};
    set_pose_history(b, std::vector<Pose>(3, Pose{center_b}), Pose{center_b + Vec3(0, 0, 0.001)});
    scene_.objects = {a, b};
    GraphBuilder(GraphConfig{}).build(scene_, graph_);
  }

  static void expect_row(const float* row, std::vector<double> expected) {
    for (size_t i = 0; i < expected.size(); ++i) {
      EXPECT_NEAR(row[i], expected[i], 1e-6) << "feature " << i;
    }
  }

  const TriangleMesh mesh_ = centered_tetrahedron();
  Scene scene_;
  Graph graph_;
};

TEST_F(TwoTetrahedra, CountsOfEveryNodeAndEdgeType) {
  EXPECT_EQ(graph_.num_mesh_nodes(), 8);
  EXPECT_EQ(graph_.object_nodes.rows(), 2);
  EXPECT_EQ(graph_.mesh_edges.size(), 24);  // 6 edges x 2 directions x 2 objects
  EXPECT_EQ(graph_.object_to_mesh.size(), 8);
  EXPECT_EQ(graph_.mesh_to_object.size(), 8);
  EXPECT_EQ(graph_.face_edges.size(), 6);  // 3 face pairs x 2 directions
  EXPECT_EQ(graph_.world_edges.size(), 0);
  EXPECT_EQ(graph_.mesh_nodes.cols(), 16);
  EXPECT_EQ(graph_.face_edges.features.cols(), 34);
}

TEST_F(TwoTetrahedra, MeshNodeFeatures) {
  // A: velocities newest first (0.02, 0, 0) then (0.01, 0, 0), each with its norm; mass, friction,
  // restitution; not kinematic; no next-step displacement.
  for (int i = 0; i < 4; ++i) {
    expect_row(graph_.mesh_nodes.row(i),
               {0.02, 0, 0, 0.02, 0.01, 0, 0, 0.01, 2.0, 0.4, 0.3, 0, 0, 0, 0, 0});
  }
  // B: at rest, kinematic, moves 0.001 up at the next step.
  for (int i = 4; i < 8; ++i) {
    expect_row(graph_.mesh_nodes.row(i),
               {0, 0, 0, 0, 0, 0, 0, 0, 0.0, 0.8, 0.7, 1, 0, 0, 0.001, 0.001});
  }
  // Object nodes carry the same features at the centre of mass.
  expect_row(graph_.object_nodes.row(0),
             {0.02, 0, 0, 0.02, 0.01, 0, 0, 0.01, 2.0, 0.4, 0.3, 0, 0, 0, 0, 0});
  expect_row(graph_.object_nodes.row(1),
             {0, 0, 0, 0, 0, 0, 0, 0, 0.0, 0.8, 0.7, 1, 0, 0, 0.001, 0.001});
}

// velocity_log_scale s adds sign(v)·ln(1 + |v|/s) of each velocity component after the velocities.
TEST_F(TwoTetrahedra, VelocityLogarithmsFollowTheVelocities) {
  GraphConfig config;
  config.velocity_log_scale = 0.001;
  Graph graph;
  GraphBuilder(config).build(scene_, graph);
  ASSERT_EQ(graph.mesh_nodes.cols(), 22);
  ASSERT_EQ(graph.object_nodes.cols(), 22);
  const double newest = std::log(21.0), oldest = std::log(11.0);  // 0.02 and 0.01 m over 0.001
  for (int i = 0; i < 4; ++i) {
    expect_row(graph.mesh_nodes.row(i), {0.02,   0, 0, 0.02, 0.01, 0,   0, 0.01, newest, 0, 0,
                                         oldest, 0, 0, 2.0,  0.4,  0.3, 0, 0,    0,      0, 0});
  }
  expect_row(graph.object_nodes.row(1),
             {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.0, 0.8, 0.7, 1, 0, 0, 0.001, 0.001});
  // A velocity along −x gives a negative logarithm.
  Scene mirrored = scene_;
  set_pose_history(mirrored.objects[0],
                   std::vector<Pose>{{Vec3(0, 0, 0)}, {Vec3(-0.01, 0, 0)}, {Vec3(-0.03, 0, 0)}});
  GraphBuilder(config).build(mirrored, graph);
  EXPECT_NEAR(graph.object_nodes.row(0)[8], -newest, 1e-6);
}

TEST_F(TwoTetrahedra, MeshAndObjectEdgeFeatures) {
  // Edge 0 of the mesh is (0, 1): receiver minus sender is +x, now and at rest.
  EXPECT_EQ(graph_.mesh_edges.senders[0], 0);
  EXPECT_EQ(graph_.mesh_edges.receivers[0], 1);
  expect_row(graph_.mesh_edges.features.row(0), {1, 0, 0, 1, 1, 0, 0, 1});
  expect_row(graph_.mesh_edges.features.row(1), {-1, 0, 0, 1, -1, 0, 0, 1});
  // Object -> node 0 of A: the node's offset from the centre, (-1/4, -1/4, -1/4).
  const double r = std::sqrt(3.0) / 4;
  EXPECT_EQ(graph_.object_to_mesh.senders[0], 0);
  EXPECT_EQ(graph_.object_to_mesh.receivers[0], 0);
  expect_row(graph_.object_to_mesh.features.row(0),
             {-0.25, -0.25, -0.25, r, -0.25, -0.25, -0.25, r});
  expect_row(graph_.mesh_to_object.features.row(0), {0.25, 0.25, 0.25, r, 0.25, 0.25, 0.25, r});
  // Node 7 (B's apex) belongs to object 1.
  EXPECT_EQ(graph_.object_to_mesh.senders[7], 1);
  EXPECT_EQ(graph_.object_to_mesh.receivers[7], 7);
}

TEST_F(TwoTetrahedra, FaceFaceEdgeFromABottomToBsSideFace) {
  // Sender: A's bottom face (nodes 0, 1, 2); closest point p_s = (0.13, 0.05, -0.25).
  // Receiver: B's face in its x = -1/4 plane (B's nodes 0, 2, 3 = global 4, 6, 7); p_r = the apex.
  int edge = -1;
  for (int e = 0; e < graph_.face_edges.size(); ++e) {
    std::vector<int> s(&graph_.face_edges.senders[3 * e], &graph_.face_edges.senders[3 * e + 3]);
    std::vector<int> r(&graph_.face_edges.receivers[3 * e],
                       &graph_.face_edges.receivers[3 * e + 3]);
    std::sort(s.begin(), s.end());
    std::sort(r.begin(), r.end());
    if (s == std::vector<int>{0, 1, 2} && r == std::vector<int>{4, 6, 7}) edge = e;
  }
  ASSERT_GE(edge, 0);
  // Senders sorted by distance to p_s: node 0 (0.461), node 1 (0.716), node 2 (0.783).
  EXPECT_EQ(graph_.face_edges.senders[3 * edge + 0], 0);
  EXPECT_EQ(graph_.face_edges.senders[3 * edge + 1], 1);
  EXPECT_EQ(graph_.face_edges.senders[3 * edge + 2], 2);
  // Receivers by distance to the apex: the apex itself (0), B's node 0 (1), B's node 2 (sqrt 2).
  EXPECT_EQ(graph_.face_edges.receivers[3 * edge + 0], 7);
  EXPECT_EQ(graph_.face_edges.receivers[3 * edge + 1], 4);
  EXPECT_EQ(graph_.face_edges.receivers[3 * edge + 2], 6);
  auto norm = [](double x, double y, double z) { return std::sqrt(x * x + y * y + z * z); };
  expect_row(graph_.face_edges.features.row(edge),
             {0,     0,     -0.05, 0.05,                // p_r - p_s
              -0.35, -0.30, 0,     norm(0.35, 0.3, 0),  // sender spans x_sj - p_s
              0.65,  -0.30, 0,     norm(0.65, 0.3, 0),  //
              -0.35, 0.70,  0,     norm(0.35, 0.7, 0),  //
              0,     0,     0,     0,                   // receiver spans x_rj - p_r
              0,     0,     -1,    1,                   //
              0,     1,     -1,    std::sqrt(2.0),      //
              -1,    0,     0,                          // n_r: B's face, outward -x
              0,     0,     -1});                       // n_s: A's bottom, outward -z
}

// face_span_limit shortens each of the six spans (columns 4-27, [x, y, z, norm] each) longer than
// the limit to that length, direction kept; d_rs, the normals and the node order stay.
TEST_F(TwoTetrahedra, SpanLimitShortensOnlyTheLongSpans) {
  GraphConfig config;
  config.face_span_limit = 0.5;
  Graph limited;
  GraphBuilder(config).build(scene_, limited);
  ASSERT_EQ(limited.face_edges.size(), graph_.face_edges.size());
  EXPECT_EQ(limited.face_edges.senders, graph_.face_edges.senders);
  EXPECT_EQ(limited.face_edges.receivers, graph_.face_edges.receivers);
  int shortened = 0;
  for (int e = 0; e < graph_.face_edges.size(); ++e) {
    const float* whole = graph_.face_edges.features.row(e);
    const float* row = limited.face_edges.features.row(e);
    std::vector<double> expected(whole, whole + 34);
    for (int block = 1; block <= 6; ++block) {
      const double length = whole[4 * block + 3];
      if (length <= 0.5) continue;
      for (int c = 0; c < 4; ++c) expected[4 * block + c] *= 0.5 / length;
      ++shortened;
    }
    expect_row(row, expected);
  }
  // Of the edge checked by hand above: one sender span (0.716) and two receiver spans (1, 1.41).
  EXPECT_GE(shortened, 3);
}

// distance_log_scale s appends ln(1 + |d_rs|/s) to each face–face row; the 34 columns before it
// are the plain ones.
TEST_F(TwoTetrahedra, DistanceLogarithmFollowsTheFaceEdgeRow) {
  GraphConfig config;
  config.distance_log_scale = 0.001;
  Graph graph;
  GraphBuilder(config).build(scene_, graph);
  ASSERT_EQ(graph.face_edges.features.cols(), 35);
  ASSERT_EQ(graph.face_edges.size(), graph_.face_edges.size());
  EXPECT_EQ(graph.face_edges.senders, graph_.face_edges.senders);
  for (int e = 0; e < graph_.face_edges.size(); ++e) {
    const float* plain = graph_.face_edges.features.row(e);
    std::vector<double> expected(plain, plain + 34);
    expected.push_back(std::log1p(plain[3] / 0.001));
    expect_row(graph.face_edges.features.row(e), expected);
  }
  // All three pairs meet at B's apex, 0.05 m below A's bottom face: ln(1 + 50).
  for (int e = 0; e < graph.face_edges.size(); ++e)
    EXPECT_NEAR(graph.face_edges.features.row(e)[34], std::log(51.0), 1e-5) << "edge " << e;
}

// contact_motion appends [u, |u|, u·n_s], u the receiver's closest point's motion over the last
// frame less the sender's. A moved +0.02 m in x and B stood still: u = (-0.02, 0, 0) on the edges
// A sends (n_s = A's bottom, -z: no approach) and (+0.02, 0, 0) on their twins.
TEST_F(TwoTetrahedra, ContactMotionOfATranslation) {
  GraphConfig config;
  config.contact_motion = true;
  Graph graph;
  GraphBuilder(config).build(scene_, graph);
  ASSERT_EQ(graph.face_edges.features.cols(), 39);
  ASSERT_EQ(graph.face_edges.size(), graph_.face_edges.size());
  for (int e = 0; e < graph_.face_edges.size(); ++e) {
    const float* plain = graph_.face_edges.features.row(e);
    std::vector<double> expected(plain, plain + 34);
    const bool a_sends = graph.node_object[graph.face_edges.senders[3 * e]] == 0;
    const Vec3 u(a_sends ? -0.02 : 0.02, 0, 0);
    const Vec3 n_s(plain[31], plain[32], plain[33]);
    expected.insert(expected.end(), {u.x(), u.y(), u.z(), u.norm(), u.dot(n_s)});
    expect_row(graph.face_edges.features.row(e), expected);
  }
}

// contact_motion_dead_zone δ shrinks u by δ along itself and zeroes it below δ: the 2 cm
// translation above reads 1.5 cm at δ = 5 mm (|u| and u·n_s with it) and nothing at δ = 3 cm,
// while the 34 columns before it stay as they were.
TEST_F(TwoTetrahedra, ContactMotionDeadZone) {
  for (const double dead_zone : {0.005, 0.03}) {
    SCOPED_TRACE("dead zone " + std::to_string(dead_zone));
    GraphConfig config;
    config.contact_motion = true;
    config.contact_motion_dead_zone = dead_zone;
    Graph graph;
    GraphBuilder(config).build(scene_, graph);
    ASSERT_EQ(graph.face_edges.features.cols(), 39);
    ASSERT_EQ(graph.face_edges.size(), graph_.face_edges.size());
    const double length = std::max(0.02 - dead_zone, 0.0);
    for (int e = 0; e < graph_.face_edges.size(); ++e) {
      const float* plain = graph_.face_edges.features.row(e);
      std::vector<double> expected(plain, plain + 34);
      const bool a_sends = graph.node_object[graph.face_edges.senders[3 * e]] == 0;
      const Vec3 u(a_sends ? -length : length, 0, 0);
      const Vec3 n_s(plain[31], plain[32], plain[33]);
      expected.insert(expected.end(), {u.x(), u.y(), u.z(), u.norm(), u.dot(n_s)});
      expect_row(graph.face_edges.features.row(e), expected);
    }
  }
}

// The same under rotation, against the rigid motions themselves: A turns about z (0.05 then
// 0.12 rad) while B slides, and each closest point's motion is where the body's last-frame pose
// puts that material point, subtracted from where it is now.
TEST_F(TwoTetrahedra, ContactMotionFollowsRigidMotion) {
  Scene scene = scene_;
  const auto turn = [](double angle) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
  };
  const std::vector<Pose> a_poses = {
      {Vec3(0, 0, 0), turn(0.0)}, {Vec3(0.01, 0, 0), turn(0.05)}, {Vec3(0.03, 0, 0), turn(0.12)}};
  const Pose b_now{scene.objects[1].centers.row(2).transpose()};
  const Pose b_before{b_now.position - Vec3(0, 0.01, -0.005), turn(-0.02)};
  const std::vector<Pose> b_poses = {b_before, b_before, b_now};
  set_pose_history(scene.objects[0], a_poses);
  set_pose_history(scene.objects[1], b_poses, b_now);
  GraphConfig config;
  config.contact_motion = true;
  Graph graph;
  GraphBuilder(config).build(scene, graph);
  ASSERT_GT(graph.face_edges.size(), 0);

  const Pose now[2] = {a_poses[2], b_now}, before[2] = {a_poses[1], b_before};
  const Points nodes[2] = {posed_vertices(mesh_, now[0]), posed_vertices(mesh_, now[1])};
  const auto motion = [&](int object, const Vec3& p) {
    const Vec3 local = now[object].orientation.conjugate() * (p - now[object].position);
    return Vec3(p - before[object].apply(local));
  };
  for (int e = 0; e < graph.face_edges.size(); ++e) {
    const float* row = graph.face_edges.features.row(e);
    const int sender = graph.face_edges.senders[3 * e],
              receiver = graph.face_edges.receivers[3 * e];
    const int s = graph.node_object[sender], r = graph.node_object[receiver];
    // The closest points from the first span of each face: p = x_j − (x_j − p).
    const Vec3 p_s = nodes[s].row(sender - 4 * s).transpose() - Vec3(row[4], row[5], row[6]);
    const Vec3 p_r = nodes[r].row(receiver - 4 * r).transpose() - Vec3(row[16], row[17], row[18]);
    const Vec3 u = motion(r, p_r) - motion(s, p_s);
    const Vec3 n_s(row[31], row[32], row[33]);
    SCOPED_TRACE("edge " + std::to_string(e));
    expect_row(row + 34, {u.x(), u.y(), u.z(), u.norm(), u.dot(n_s)});
  }
}

TEST_F(TwoTetrahedra, ReverseEdgeSwapsRoles) {
  // Every face edge has a twin with senders and receivers exchanged and d_rs negated.
  for (int e = 0; e < graph_.face_edges.size(); e += 2) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(graph_.face_edges.senders[3 * e + k], graph_.face_edges.receivers[3 * (e + 1) + k]);
    }
    for (int c = 0; c < 4; ++c) {
      const float sign = c < 3 ? -1.0f : 1.0f;
      EXPECT_FLOAT_EQ(graph_.face_edges.features.row(e + 1)[c],
                      sign * graph_.face_edges.features.row(e)[c]);
    }
  }
}

TEST(GraphBuilder, FloorMeshAndImplicitFloor) {
  const auto fixture = testing::make_random_scene(5, 6, 0.8);
  GraphConfig config;
  Graph graph;
  GraphBuilder(config).build(fixture.scene, graph);
  // The floor is one more kinematic object of 4 nodes and 2 faces.
  EXPECT_EQ(graph.num_objects(), 7);
  EXPECT_EQ(graph.object_first_node[7] - graph.object_first_node[6], 4);
  EXPECT_EQ(graph.object_kinematic[6], 1);

  config.floor = FloorModel::kImplicit;
  GraphBuilder(config).build(fixture.scene, graph);
  EXPECT_EQ(graph.num_objects(), 6);
  EXPECT_EQ(graph.mesh_nodes.cols(), 18);
  int near = 0;
  for (int i = 0; i < graph.num_mesh_nodes(); ++i) {
    const float* row = graph.mesh_nodes.row(i);
    const int object = graph.node_object[i];
    const int local = i - graph.object_first_node[object];
    const double z = fixture.scene.objects[object].positions(
        2 * fixture.scene.objects[object].mesh->num_vertices() + local, 2);
    EXPECT_EQ(row[16], z < 0.1 ? 1.0f : 0.0f);
    EXPECT_FLOAT_EQ(row[17], z < 0.1 ? float(z) : 0.0f);
    near += z < 0.1;
  }
  EXPECT_GT(near, 0);
}

TEST(GraphBuilder, NoObjectNodesAblationDropsObjectsEdges) {
  const auto fixture = testing::make_random_scene(5, 6, 0.8);
  GraphConfig config;
  config.object_nodes = false;
  Graph graph;
  GraphBuilder(config).build(fixture.scene, graph);
  EXPECT_EQ(graph.object_nodes.rows(), 0);
  EXPECT_EQ(graph.object_to_mesh.size(), 0);
  EXPECT_EQ(graph.mesh_to_object.size(), 0);
  EXPECT_GT(graph.face_edges.size(), 0);
}

TEST(GraphBuilder, BatchIsTheConcatenationOfItsScenes) {
  const auto first = testing::make_random_scene(1, 5, 0.8);
  const auto second = testing::make_random_scene(2, 7, 0.8);
  GraphBuilder builder(GraphConfig{});
  Graph g1, g2, batch;
  builder.build(first.scene, g1);
  builder.build(second.scene, g2);
  const Scene scenes[] = {first.scene, second.scene};
  builder.build(scenes, batch);
  ASSERT_EQ(batch.num_scenes(), 2);
  EXPECT_EQ(batch.scene_first_object[1], g1.num_objects());
  EXPECT_EQ(batch.num_mesh_nodes(), g1.num_mesh_nodes() + g2.num_mesh_nodes());
  EXPECT_EQ(batch.mesh_nodes.matrix().topRows(g1.num_mesh_nodes()), g1.mesh_nodes.matrix());
  EXPECT_EQ(batch.mesh_nodes.matrix().bottomRows(g2.num_mesh_nodes()), g2.mesh_nodes.matrix());
  ASSERT_EQ(batch.face_edges.size(), g1.face_edges.size() + g2.face_edges.size());
  const int offset = g1.num_mesh_nodes();
  for (int i = 0; i < 3 * g2.face_edges.size(); ++i) {
    EXPECT_EQ(batch.face_edges.receivers[3 * g1.face_edges.size() + i],
              g2.face_edges.receivers[i] + offset);
  }
  for (int e = 0; e < g2.object_to_mesh.size(); ++e) {
    EXPECT_EQ(batch.object_to_mesh.senders[g1.object_to_mesh.size() + e],
              g2.object_to_mesh.senders[e] + g1.num_objects());
  }
}

}  // namespace
}  // namespace fignet
