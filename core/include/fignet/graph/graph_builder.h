// Builds the FIGNet input graph (seed C.1.1, C.2) of one or more scenes into a reusable Graph.
// A builder holds the immutable config and the per-step scratch (hierarchies, pair lists), so one
// builder per thread; a steady-state build allocates nothing.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "fignet/graph/config.h"
#include "fignet/graph/contacts.h"
#include "fignet/graph/graph.h"
#include "fignet/graph/scene.h"

namespace fignet {

// The floor mesh used for FloorModel::kMesh: a flat square at z = 0 split into 2·segments²
// triangles facing +z.
TriangleMesh make_floor_mesh(double half_extent, int segments);

// The collision pairs a contact search found in one scene: face pairs (CollisionEdges::kFaceFace)
// or node pairs (kNodeNode), with object indices into the scene's objects, the mesh floor last.
struct SceneContacts {
  std::vector<FacePair> faces;
  std::vector<NodePair> nodes;
};

class GraphBuilder {
 public:
  explicit GraphBuilder(const GraphConfig& config);

  const GraphConfig& config() const { return config_; }
  const FeatureSizes& sizes() const { return sizes_; }

  // Builds the concatenated graph of `scenes`. Throws ConfigError naming the scene, object and
  // field when an input is inconsistent (history length, missing kinematic targets, NaN).
  void build(std::span<const Scene> scenes, Graph& graph);
  void build(const Scene& scene, Graph& graph) { build(std::span(&scene, 1), graph); }

  // Builds one scene with the object pairs to examine given by the caller (for example from a
  // physics engine's broadphase) instead of the builder's own sweep. Object indices follow
  // scene.objects, with the floor (when modelled as a mesh) at index scene.objects.size().
  void build_with_candidates(const Scene& scene, std::span<const ObjectPair> candidates,
                             Graph& graph);

  // Builds `scenes` with each one's collision pairs given (contacts[s] for scenes[s]) instead of
  // searched: for scenes cut from searched ones (FreeFlightSplit), whose search stands. Throws
  // ConfigError when the counts differ or a pair names an object, face or node a scene lacks.
  void build_with_contacts(std::span<const Scene> scenes, std::span<const SceneContacts> contacts,
                           Graph& graph);

  // Which objects build_with_candidates(scene, candidates) would give a collision edge (face–face
  // or node–node), or, with an implicit floor, would place within the collision radius of it: one
  // flag per object, the mesh floor last when there is one. The network's prediction for an object
  // without any depends on nothing outside it (a physics engine can advance it itself).
  // With `found`, the search's collision pairs too, which build_with_contacts can reuse.
  void find_interacting_objects(const Scene& scene, std::span<const ObjectPair> candidates,
                                std::vector<char>& interacting, SceneContacts* found = nullptr);
  // The same with the pairs build(scene) would examine (the builder's own sweep).
  void find_interacting_objects(const Scene& scene, std::vector<char>& interacting,
                                SceneContacts* found = nullptr);

  // The face pairs found by the last build, with object indices into the graph's objects.
  std::span<const FacePair> face_pairs() const { return face_pairs_; }

 private:
  // Searches each scene's collision pairs (among `candidates` when given) unless `contacts` gives
  // them.
  void build_scenes(std::span<const Scene> scenes, const std::span<const ObjectPair>* candidates,
                    std::span<const SceneContacts> contacts, Graph& graph);
  void validate_scene(const Scene& scene, int scene_index) const;
  // The scene's objects into objects_ (validated; the mesh floor appended).
  void gather_objects(const Scene& scene, int scene_index);
  PosedMesh current_pose(const SceneObject& object) const;
  // The pairs to search into pairs_: the caller's (checked), or the builder's own sweep.
  void select_pairs(const std::span<const ObjectPair>* candidates);
  void find_interacting(const Scene& scene, const std::span<const ObjectPair>* candidates,
                        std::vector<char>& interacting, SceneContacts* found);
  // Throws unless every pair of `contacts` names objects, faces and nodes of objects_.
  void validate_contacts(const SceneContacts& contacts, int scene_index) const;
  const SceneObject& floor_object(const Scene& scene, int scene_index);

  GraphConfig config_;
  FeatureSizes sizes_;
  TriangleMesh floor_mesh_;
  // Scratch reused across builds.
  std::vector<SceneObject> floor_objects_;
  std::vector<const SceneObject*> objects_;
  std::vector<const Floor*> object_floor_;
  std::vector<PosedMesh> posed_;
  ContactFinder contacts_;
  std::vector<ObjectPair> pairs_, scene_pairs_;
  std::vector<FacePair> face_pairs_, scene_face_pairs_;
  std::vector<NodePair> node_pairs_;
};

}  // namespace fignet
