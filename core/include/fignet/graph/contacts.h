// Broad and narrow phase between the posed meshes of a scene: which objects are near each other,
// which of their faces (or nodes) lie within the collision radius, and their closest points.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fignet/geometry/bvh.h"
#include "fignet/geometry/mesh.h"

namespace fignet {

// A mesh at its current pose: the rest mesh's topology with moved vertex positions.
struct PosedMesh {
  const TriangleMesh* mesh = nullptr;
  const double* positions = nullptr;  // num_vertices x 3, row-major, world frame
  bool kinematic = false;
  // The same vertices one frame earlier, where the graph's features need their motion (null:
  // unknown, read as still).
  const double* previous = nullptr;

  Eigen::Map<const Points> vertices() const { return {positions, mesh->num_vertices(), 3}; }
  Eigen::Map<const Points> previous_vertices() const { return {previous, mesh->num_vertices(), 3}; }
};

struct ObjectPair {
  std::int32_t a = 0, b = 0;  // a < b
  friend bool operator==(const ObjectPair&, const ObjectPair&) = default;
};

struct FacePair {
  std::int32_t object_a, face_a, object_b, face_b;  // object_a < object_b
  Vec3 point_a, point_b;                            // closest points on each face
  double distance;
};

struct NodePair {
  std::int32_t object_a, node_a, object_b, node_b;  // object_a < object_b
  double distance;
};

// Keeps one hierarchy per object between calls: rebuilt when the object's mesh changes, refitted
// otherwise, so a steady-state step allocates nothing.
class ContactFinder {
 public:
  // Prepares face (and, if wanted, node) hierarchies for the current poses.
  void update(std::span<const PosedMesh> objects, bool with_node_hierarchies);

  // Object pairs whose bounds are within `radius` (sweep and prune along x). Pairs of two
  // kinematic objects are skipped: neither is predicted, so their contact carries no information.
  void find_candidate_pairs(double radius, std::vector<ObjectPair>& out);

  // Every pair of faces of the candidate objects within `radius`, with exact closest points.
  void find_face_pairs(std::span<const ObjectPair> candidates, double radius,
                       std::vector<FacePair>& out) const;
  // Both phases at once: the candidate pairs (kept in `pairs`) and their face pairs within
  // `radius`.
  void find_all_face_pairs(double radius, std::vector<ObjectPair>& pairs,
                           std::vector<FacePair>& out) {
    find_candidate_pairs(radius, pairs);
    find_face_pairs(pairs, radius, out);
  }

  // Every pair of nodes of the candidate objects within `radius`.
  void find_node_pairs(std::span<const ObjectPair> candidates, double radius,
                       std::vector<NodePair>& out) const;

  const Aabb& bounds(int object) const { return slots_[object].faces.bounds(); }

 private:
  struct Slot {
    const TriangleMesh* mesh = nullptr;
    const double* positions = nullptr;
    bool kinematic = false;
    bool has_node_hierarchy = false;
    Bvh faces;
    Bvh nodes;
  };
  std::vector<Slot> slots_;
  std::vector<Aabb> boxes_;          // scratch: primitive boxes of one object
  std::vector<std::int32_t> sweep_;  // scratch: objects sorted by min x
};

}  // namespace fignet
