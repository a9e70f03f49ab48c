// Reordering vertices within faces, faces within a mesh, vertices within a mesh, or objects within
// a scene gives the same graph up to that permutation (seed C.1.1: sorting face nodes by distance
// to the closest point makes the model permutation-equivariant).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>

#include "fignet/graph/graph_builder.h"
#include "scene_fixtures.h"

namespace fignet {
namespace {

// A node named by what it is, not where it is stored: (original object, original vertex).
using NodeId = std::pair<int, int>;
using Features = std::vector<float>;

struct CanonicalGraph {
  std::map<NodeId, Features> nodes;
  std::map<std::pair<NodeId, NodeId>, Features> mesh_edges, object_mesh_edges;
  std::map<std::pair<std::vector<NodeId>, std::vector<NodeId>>, Features> face_edges;
};

Features row_of(const FeatureMatrix& m, int r) {
  return Features(m.row(r), m.row(r) + m.cols());
}

// `node_id[i]` names global mesh node i; `object_id[o]` names global object o.
CanonicalGraph canonical(const Graph& g, const std::vector<NodeId>& node_id,
                         const std::vector<int>& object_id) {
  CanonicalGraph c;
  for (int i = 0; i < g.num_mesh_nodes(); ++i) c.nodes[node_id[i]] = row_of(g.mesh_nodes, i);
  for (int e = 0; e < g.mesh_edges.size(); ++e) {
    c.mesh_edges[{node_id[g.mesh_edges.senders[e]], node_id[g.mesh_edges.receivers[e]]}] =
        row_of(g.mesh_edges.features, e);
  }
  for (int e = 0; e < g.object_to_mesh.size(); ++e) {
    c.object_mesh_edges[{{object_id[g.object_to_mesh.senders[e]], -1},
                         node_id[g.object_to_mesh.receivers[e]]}] =
        row_of(g.object_to_mesh.features, e);
  }
  for (int e = 0; e < g.face_edges.size(); ++e) {
    std::vector<NodeId> s, r;
    for (int k = 0; k < 3; ++k) {
      s.push_back(node_id[g.face_edges.senders[3 * e + k]]);
      r.push_back(node_id[g.face_edges.receivers[3 * e + k]]);
    }
    EXPECT_TRUE(c.face_edges.emplace(std::pair(s, r), row_of(g.face_edges.features, e)).second);
  }
  return c;
}

template <class Key>
void expect_same(const std::map<Key, Features>& a, const std::map<Key, Features>& b,
                 const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  auto ib = b.begin();
  for (auto ia = a.begin(); ia != a.end(); ++ia, ++ib) {
    ASSERT_TRUE(ia->first == ib->first) << what << ": different edge sets";
    for (size_t k = 0; k < ia->second.size(); ++k) {
      // Same geometry, different arithmetic order: equal to float rounding.
      ASSERT_NEAR(ia->second[k], ib->second[k], 2e-6) << what << ", feature " << k;
    }
  }
}

void expect_same(const CanonicalGraph& a, const CanonicalGraph& b) {
  expect_same(a.nodes, b.nodes, "mesh nodes");
  expect_same(a.mesh_edges, b.mesh_edges, "mesh edges");
  expect_same(a.object_mesh_edges, b.object_mesh_edges, "object-mesh edges");
  expect_same(a.face_edges, b.face_edges, "face edges");
  EXPECT_GT(a.face_edges.size(), 0u);
}

// Builds the graph of a scene whose object o is original object `order[o]` and whose vertex v of
// object o is original vertex `vertex_of[o][v]`.
CanonicalGraph build_canonical(const Scene& scene, const std::vector<int>& order,
                               const std::vector<std::vector<int>>& vertex_of) {
  Graph graph;
  GraphBuilder(GraphConfig{}).build(scene, graph);
  std::vector<NodeId> node_id(graph.num_mesh_nodes());
  std::vector<int> object_id(graph.num_objects());
  for (int o = 0; o < graph.num_objects(); ++o) {
    const bool floor = o == int(order.size());
    object_id[o] = floor ? -1 : order[o];
    for (int i = graph.object_first_node[o]; i < graph.object_first_node[o + 1]; ++i) {
      const int local = i - graph.object_first_node[o];
      node_id[i] = floor ? NodeId{-1, local} : NodeId{order[o], vertex_of[o][local]};
    }
  }
  return canonical(graph, node_id, object_id);
}

class Permutation : public ::testing::Test {
 protected:
  void SetUp() override {
    fixture_ = testing::make_random_scene(21, 8, 0.7);
    for (size_t o = 0; o < fixture_.scene.objects.size(); ++o) {
      identity_order_.push_back(int(o));
      std::vector<int> v(fixture_.scene.objects[o].mesh->num_vertices());
      std::iota(v.begin(), v.end(), 0);
      identity_vertices_.push_back(v);
    }
    reference_ = build_canonical(fixture_.scene, identity_order_, identity_vertices_);
  }

  // Replaces object o's mesh with one whose faces and vertices are permuted; the positions follow.
  void permute_mesh(Scene& scene, int o, std::mt19937& rng, bool rotate_faces, bool shuffle_faces,
                    std::vector<int>* vertex_of) {
    const TriangleMesh& mesh = *scene.objects[o].mesh;
    const int v = mesh.num_vertices();
    std::vector<int> old_of_new(v);
    std::iota(old_of_new.begin(), old_of_new.end(), 0);
    if (vertex_of) std::shuffle(old_of_new.begin(), old_of_new.end(), rng);
    std::vector<int> new_of_old(v);
    for (int n = 0; n < v; ++n) new_of_old[old_of_new[n]] = n;
    Points vertices(v, 3);
    for (int n = 0; n < v; ++n) vertices.row(n) = mesh.vertices().row(old_of_new[n]);
    std::vector<int> face_order(mesh.num_faces());
    std::iota(face_order.begin(), face_order.end(), 0);
    if (shuffle_faces) std::shuffle(face_order.begin(), face_order.end(), rng);
    Triangles faces(mesh.num_faces(), 3);
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const int shift = rotate_faces ? int(rng() % 3) : 0;  // cyclic: keeps the orientation
      for (int k = 0; k < 3; ++k) {
        faces(f, k) = new_of_old[mesh.faces()(face_order[f], (k + shift) % 3)];
      }
    }
    meshes_.push_back(std::make_unique<TriangleMesh>(mesh.name(), vertices, faces));
    SceneObject& object = scene.objects[o];
    Points positions = object.positions;
    for (int step = 0; step * v < positions.rows(); ++step) {
      for (int n = 0; n < v; ++n) {
        positions.row(step * v + n) = object.positions.row(step * v + old_of_new[n]);
      }
    }
    object.positions = positions;
    if (object.kinematic) {
      Points next = object.next_positions;
      for (int n = 0; n < v; ++n) next.row(n) = object.next_positions.row(old_of_new[n]);
      object.next_positions = next;
    }
    object.mesh = meshes_.back().get();
    if (vertex_of) *vertex_of = old_of_new;
  }

  testing::RandomScene fixture_;
  std::vector<int> identity_order_;
  std::vector<std::vector<int>> identity_vertices_;
  CanonicalGraph reference_;
  std::vector<std::unique_ptr<TriangleMesh>> meshes_;
};

TEST_F(Permutation, VertexOrderWithinFaces) {
  std::mt19937 rng(1);
  Scene scene = fixture_.scene;
  for (int o = 0; o < int(scene.objects.size()); ++o)
    permute_mesh(scene, o, rng, true, false, nullptr);
  expect_same(reference_, build_canonical(scene, identity_order_, identity_vertices_));
}

TEST_F(Permutation, FaceOrderWithinMeshes) {
  std::mt19937 rng(2);
  Scene scene = fixture_.scene;
  for (int o = 0; o < int(scene.objects.size()); ++o)
    permute_mesh(scene, o, rng, false, true, nullptr);
  expect_same(reference_, build_canonical(scene, identity_order_, identity_vertices_));
}

TEST_F(Permutation, VertexOrderWithinMeshes) {
  std::mt19937 rng(3);
  Scene scene = fixture_.scene;
  auto vertex_of = identity_vertices_;
  for (int o = 0; o < int(scene.objects.size()); ++o) {
    permute_mesh(scene, o, rng, true, true, &vertex_of[o]);
  }
  expect_same(reference_, build_canonical(scene, identity_order_, vertex_of));
}

TEST_F(Permutation, ObjectOrderWithinScene) {
  std::mt19937 rng(4);
  std::vector<int> order = identity_order_;
  std::shuffle(order.begin(), order.end(), rng);
  Scene scene;
  scene.floor = fixture_.scene.floor;
  std::vector<std::vector<int>> vertex_of;
  for (int o : order) {
    scene.objects.push_back(fixture_.scene.objects[o]);
    vertex_of.push_back(identity_vertices_[o]);
  }
  expect_same(reference_, build_canonical(scene, order, vertex_of));
}

}  // namespace
}  // namespace fignet
