#include "fignet/graph/graph_builder.h"

#include <fmt/format.h>

#include "features.h"
#include "fignet/error.h"

namespace fignet {

TriangleMesh make_floor_mesh(double half_extent, int segments) {
  const int n = segments + 1;
  Points vertices(n * n, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      vertices.row(i * n + j) << -half_extent + 2.0 * half_extent * i / segments,
          -half_extent + 2.0 * half_extent * j / segments, 0.0;
    }
  }
  Triangles faces(2 * segments * segments, 3);
  int f = 0;
  for (int i = 0; i < segments; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = i * n + j, b = (i + 1) * n + j, c = (i + 1) * n + j + 1, d = i * n + j + 1;
      faces.row(f++) << a, b, c;  // counter-clockwise seen from +z: normal +z
      faces.row(f++) << a, c, d;
    }
  }
  return TriangleMesh("floor", std::move(vertices), std::move(faces));
}

GraphBuilder::GraphBuilder(const GraphConfig& config)
    : config_((config.validate(), config)),
      sizes_(feature_sizes(config)),
      floor_mesh_(make_floor_mesh(config.floor_half_extent, config.floor_segments)) {}

void GraphBuilder::validate_scene(const Scene& scene, int scene_index) const {
  const int steps = config_.history + 1;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const SceneObject& object = scene.objects[o];
    auto fail = [&](const std::string& what) {
      throw ConfigError(fmt::format("scene {}, object {} ('{}'): {}", scene_index, o,
                                    object.mesh ? object.mesh->name() : "", what));
    };
    if (object.mesh == nullptr) fail("has no mesh");
    const Eigen::Index v = object.mesh->num_vertices();
    if (object.positions.rows() != steps * v) {
      fail(fmt::format("positions has {} rows; expected (history + 1) x vertices = {} x {} = {}",
                       object.positions.rows(), steps, v, steps * v));
    }
    if (object.centers.rows() != steps) {
      fail(fmt::format("centers has {} rows; expected history + 1 = {}", object.centers.rows(),
                       steps));
    }
    if (object.kinematic && object.next_positions.rows() != v) {
      fail(fmt::format("is kinematic but next_positions has {} rows; expected {}",
                       object.next_positions.rows(), v));
    }
    if (!object.positions.allFinite() || !object.centers.allFinite() ||
        (object.kinematic &&
         (!object.next_positions.allFinite() || !object.next_center.allFinite()))) {
      fail("has a non-finite position");
    }
  }
}

const SceneObject& GraphBuilder::floor_object(const Scene& scene, int scene_index) {
  if (floor_objects_.size() <= static_cast<size_t>(scene_index)) {
    floor_objects_.resize(scene_index + 1);
  }
  SceneObject& floor = floor_objects_[scene_index];
  const int steps = config_.history + 1;
  const Eigen::Index v = floor_mesh_.num_vertices();
  floor.mesh = &floor_mesh_;
  floor.kinematic = true;
  floor.properties = scene.floor->properties;
  floor.positions.resize(steps * v, 3);
  floor.centers.resize(steps, 3);
  const Vec3 center(scene.floor->center_x, scene.floor->center_y, scene.floor->height);
  const Points lifted = floor_mesh_.vertices().rowwise() + center.transpose();
  for (int k = 0; k < steps; ++k) {
    floor.positions.middleRows(k * v, v) = lifted;
    floor.centers.row(k) = center.transpose();
  }
  floor.next_positions = lifted;
  floor.next_center = center;
  return floor;
}

void GraphBuilder::gather_objects(const Scene& scene, int scene_index) {
  validate_scene(scene, scene_index);
  objects_.clear();
  for (const SceneObject& object : scene.objects) objects_.push_back(&object);
  if (config_.floor == FloorModel::kMesh && scene.floor) {
    objects_.push_back(&floor_object(scene, scene_index));
  }
}

PosedMesh GraphBuilder::current_pose(const SceneObject& object) const {
  const size_t v = object.mesh->num_vertices();
  const size_t current_row = static_cast<size_t>(config_.history) * v;
  const double* current = object.positions.data() + current_row * 3;
  return {object.mesh, current, object.kinematic, current - v * 3};
}

void GraphBuilder::select_pairs(const std::span<const ObjectPair>* candidates) {
  if (!candidates) {
    contacts_.find_candidate_pairs(config_.collision_radius, pairs_);
    return;
  }
  pairs_.clear();
  const int n = static_cast<int>(objects_.size());
  for (const ObjectPair& pair : *candidates) {
    if (pair.a < 0 || pair.b < 0 || pair.a >= n || pair.b >= n || pair.a == pair.b) {
      throw ConfigError(fmt::format(
          "candidate pair ({}, {}) is not a pair of the scene's {} objects", pair.a, pair.b, n));
    }
    // Neither of two kinematic objects is predicted: their contact carries no information.
    if (posed_[pair.a].kinematic && posed_[pair.b].kinematic) continue;
    pairs_.push_back({std::min(pair.a, pair.b), std::max(pair.a, pair.b)});
  }
}

void GraphBuilder::find_interacting_objects(const Scene& scene,
                                            std::span<const ObjectPair> candidates,
                                            std::vector<char>& interacting, SceneContacts* found) {
  find_interacting(scene, &candidates, interacting, found);
}

void GraphBuilder::find_interacting_objects(const Scene& scene, std::vector<char>& interacting,
                                            SceneContacts* found) {
  find_interacting(scene, nullptr, interacting, found);
}

void GraphBuilder::find_interacting(const Scene& scene,
                                    const std::span<const ObjectPair>* candidates,
                                    std::vector<char>& interacting, SceneContacts* found) {
  gather_objects(scene, 0);
  posed_.clear();
  for (const SceneObject* object : objects_) posed_.push_back(current_pose(*object));
  const bool face_collisions = config_.collisions == CollisionEdges::kFaceFace;
  contacts_.update(posed_, !face_collisions);
  select_pairs(candidates);
  interacting.assign(objects_.size(), 0);
  // The same search build() makes, into the caller's lists when it keeps them: a collision edge
  // marks both of its objects.
  std::vector<FacePair>& faces = found ? found->faces : scene_face_pairs_;
  std::vector<NodePair>& nodes = found ? found->nodes : node_pairs_;
  faces.clear();
  nodes.clear();
  if (face_collisions) {
    contacts_.find_face_pairs(pairs_, config_.collision_radius, faces);
    for (const FacePair& pair : faces) interacting[pair.object_a] = interacting[pair.object_b] = 1;
  } else {
    contacts_.find_node_pairs(pairs_, config_.collision_radius, nodes);
    for (const NodePair& pair : nodes) interacting[pair.object_a] = interacting[pair.object_b] = 1;
  }
  // An implicit floor has no edges; a node within the radius sees it in its features.
  if (config_.floor != FloorModel::kImplicit || !scene.floor) return;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const double lowest = posed_[o].vertices().col(2).minCoeff();
    if (!scene.objects[o].kinematic && lowest - scene.floor->height < config_.collision_radius) {
      interacting[o] = 1;
    }
  }
}

void GraphBuilder::validate_contacts(const SceneContacts& contacts, int scene_index) const {
  const int objects = static_cast<int>(objects_.size());
  auto check = [&](const char* kind, size_t p, int object_a, int index_a, int object_b, int index_b,
                   bool faces) {
    auto element_count = [&](int o) {
      return faces ? objects_[o]->mesh->num_faces() : objects_[o]->mesh->num_vertices();
    };
    if (object_a < 0 || object_b >= objects || object_a >= object_b) {
      throw ConfigError(fmt::format(
          "scene {}: given {} pair {} joins objects {} and {}; expected a < b among the scene's {} "
          "objects",
          scene_index, kind, p, object_a, object_b, objects));
    }
    if (index_a < 0 || index_a >= element_count(object_a) || index_b < 0 ||
        index_b >= element_count(object_b)) {
      throw ConfigError(fmt::format(
          "scene {}: given {} pair {} names {} {} of object {} and {} of object {}, which have {} "
          "and {}",
          scene_index, kind, p, faces ? "faces" : "nodes", index_a, object_a, index_b, object_b,
          element_count(object_a), element_count(object_b)));
    }
  };
  for (size_t p = 0; p < contacts.faces.size(); ++p) {
    const FacePair& pair = contacts.faces[p];
    check("face", p, pair.object_a, pair.face_a, pair.object_b, pair.face_b, true);
  }
  for (size_t p = 0; p < contacts.nodes.size(); ++p) {
    const NodePair& pair = contacts.nodes[p];
    check("node", p, pair.object_a, pair.node_a, pair.object_b, pair.node_b, false);
  }
}

void GraphBuilder::build(std::span<const Scene> scenes, Graph& graph) {
  build_scenes(scenes, nullptr, {}, graph);
}

void GraphBuilder::build_with_candidates(const Scene& scene, std::span<const ObjectPair> candidates,
                                         Graph& graph) {
  build_scenes(std::span(&scene, 1), &candidates, {}, graph);
}

void GraphBuilder::build_with_contacts(std::span<const Scene> scenes,
                                       std::span<const SceneContacts> contacts, Graph& graph) {
  if (contacts.size() != scenes.size()) {
    throw ConfigError(fmt::format("build_with_contacts: {} scenes but contacts for {}",
                                  scenes.size(), contacts.size()));
  }
  build_scenes(scenes, nullptr, contacts, graph);
}

void GraphBuilder::build_scenes(std::span<const Scene> scenes,
                                const std::span<const ObjectPair>* candidates,
                                std::span<const SceneContacts> contacts, Graph& graph) {
  graph.mesh_nodes.reset(sizes_.mesh_node);
  graph.object_nodes.reset(sizes_.object_node);
  graph.mesh_edges.reset(sizes_.mesh_edge);
  graph.object_to_mesh.reset(sizes_.mesh_edge);
  graph.mesh_to_object.reset(sizes_.mesh_edge);
  graph.world_edges.reset(sizes_.world_edge);
  graph.face_edges.reset(sizes_.face_edge);
  graph.node_object.clear();
  graph.node_kinematic.clear();
  graph.object_first_node.assign(1, 0);
  graph.object_kinematic.clear();
  graph.scene_first_object.assign(1, 0);
  face_pairs_.clear();

  const bool face_collisions = config_.collisions == CollisionEdges::kFaceFace;
  for (size_t s = 0; s < scenes.size(); ++s) {
    const Scene& scene = scenes[s];

    // 1. The scene's objects, with the floor appended when it is a mesh.
    gather_objects(scene, static_cast<int>(s));
    const Floor* implicit_floor =
        config_.floor == FloorModel::kImplicit && scene.floor ? &*scene.floor : nullptr;

    // 2. Nodes and the edges inside each object.
    const int first_object = graph.num_objects();
    posed_.clear();
    for (size_t o = 0; o < objects_.size(); ++o) {
      const SceneObject& object = *objects_[o];
      const int object_index = first_object + static_cast<int>(o);
      const int first = graph.num_mesh_nodes();
      const int v = object.mesh->num_vertices();
      const bool internal_edges = config_.static_internal_edges || !object.kinematic;
      detail::append_mesh_nodes(config_, object, implicit_floor, graph.mesh_nodes);
      if (config_.mesh_edges && internal_edges) {
        detail::append_mesh_edges(object, first, graph.mesh_edges);
      }
      if (config_.object_nodes) {
        detail::append_object_node(config_, object, graph.object_nodes);
        if (internal_edges) {
          detail::append_object_mesh_edges(object, object_index, first, graph.object_to_mesh,
                                           graph.mesh_to_object);
        }
      }
      graph.node_object.insert(graph.node_object.end(), v, object_index);
      graph.node_kinematic.insert(graph.node_kinematic.end(), v, object.kinematic ? 1 : 0);
      graph.object_first_node.push_back(first + v);
      graph.object_kinematic.push_back(object.kinematic ? 1 : 0);
      posed_.push_back(current_pose(object));
    }

    // 3. Collision edges between objects within the collision radius: searched, or as given.
    const std::vector<FacePair>* scene_faces = &scene_face_pairs_;
    const std::vector<NodePair>* scene_nodes = &node_pairs_;
    if (contacts.empty()) {
      contacts_.update(posed_, !face_collisions);
      select_pairs(candidates);
      if (face_collisions) {
        contacts_.find_face_pairs(pairs_, config_.collision_radius, scene_face_pairs_);
      } else {
        contacts_.find_node_pairs(pairs_, config_.collision_radius, node_pairs_);
      }
    } else {
      validate_contacts(contacts[s], static_cast<int>(s));
      scene_faces = &contacts[s].faces;
      scene_nodes = &contacts[s].nodes;
    }
    auto first_node = [&](int local_object) {
      return graph.object_first_node[first_object + local_object];
    };
    if (face_collisions) {
      for (FacePair pair : *scene_faces) {
        detail::append_face_edges(config_, pair, posed_[pair.object_a], posed_[pair.object_b],
                                  first_node(pair.object_a), first_node(pair.object_b),
                                  graph.face_edges);
        pair.object_a += first_object;
        pair.object_b += first_object;
        face_pairs_.push_back(pair);
      }
    } else {
      for (const NodePair& pair : *scene_nodes) {
        detail::append_world_edges(pair, posed_[pair.object_a], posed_[pair.object_b],
                                   first_node(pair.object_a), first_node(pair.object_b),
                                   graph.world_edges);
      }
    }
    graph.scene_first_object.push_back(graph.num_objects());
  }
}

}  // namespace fignet
