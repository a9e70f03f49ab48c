#include "fignet/rollout/free_flight.h"

#include <fmt/format.h>

#include "fignet/error.h"
#include "fignet/rollout/rigid_fit.h"

namespace fignet {

Pose free_flight_pose(const Pose& previous, const Pose& current, const Vec3& gravity_step) {
  Pose next;
  next.position = 2.0 * current.position - previous.position + gravity_step;
  next.orientation =
      (current.orientation * previous.orientation.conjugate() * current.orientation).normalized();
  return next;
}

void free_flight_accelerations(const SceneObject& object, const Vec3& gravity_step,
                               Eigen::Ref<Points> rows) {
  const Points& rest = object.mesh->vertices();
  const int steps = object.num_steps();
  const auto current = object.positions_at(steps - 1);
  const auto previous = object.positions_at(steps - 2);
  const Pose next = free_flight_pose(fit_rigid_transform(rest, previous),
                                     fit_rigid_transform(rest, current), gravity_step);
  rows = posed_vertices(*object.mesh, next) - 2.0 * current + previous;
}

void FreeFlightSplit::split(GraphBuilder& builder, const Scene& scene,
                            const std::span<const ObjectPair>* candidates, Scene& kept,
                            SceneContacts& kept_contacts) {
  if (candidates) {
    builder.find_interacting_objects(scene, *candidates, interacting_, &kept_contacts);
  } else {
    builder.find_interacting_objects(scene, interacting_, &kept_contacts);
  }
  keep(scene, candidates, kept, kept_contacts);
}

void FreeFlightSplit::split_searched(const Scene& scene, std::span<const char> interacting,
                                     const SceneContacts& contacts,
                                     const std::span<const ObjectPair>* candidates, Scene& kept,
                                     SceneContacts& kept_contacts) {
  // One flag per object, and one more for a mesh floor (the builder appends it to any scene).
  const size_t objects = scene.objects.size();
  if (interacting.size() != objects && interacting.size() != objects + 1) {
    throw ConfigError(fmt::format(
        "FreeFlightSplit: {} interaction flags for a scene of {} objects; expected {} or {} (with "
        "a mesh floor)",
        interacting.size(), objects, objects, objects + 1));
  }
  // Both objects of a collision pair have an edge; anything else is not this scene's search.
  auto check = [&](const char* kind, size_t p, int a, int b) {
    const int flags = static_cast<int>(interacting.size());
    if (a < 0 || b < 0 || a >= flags || b >= flags || !interacting[a] || !interacting[b]) {
      throw ConfigError(fmt::format(
          "FreeFlightSplit: {} pair {} joins objects {} and {}, but the search's {} flags do not "
          "mark both as interacting",
          kind, p, a, b, flags));
    }
  };
  for (size_t p = 0; p < contacts.faces.size(); ++p) {
    check("face", p, contacts.faces[p].object_a, contacts.faces[p].object_b);
  }
  for (size_t p = 0; p < contacts.nodes.size(); ++p) {
    check("node", p, contacts.nodes[p].object_a, contacts.nodes[p].object_b);
  }
  interacting_.assign(interacting.begin(), interacting.end());
  kept_contacts = contacts;  // copy-assigned: a steady-state step reuses the last one's buffers
  keep(scene, candidates, kept, kept_contacts);
}

void FreeFlightSplit::keep(const Scene& scene, const std::span<const ObjectPair>* candidates,
                           Scene& kept, SceneContacts& kept_contacts) {
  // interacting_ may end with the mesh floor, which builds append whatever the scene holds.
  const size_t objects = scene.objects.size();
  kept_index_.assign(objects + 1, -1);
  kept_objects_.clear();
  for (size_t o = 0; o < objects; ++o) {
    if (!interacting_[o]) continue;
    kept_index_[o] = static_cast<int>(kept_objects_.size());
    kept_objects_.push_back(static_cast<int>(o));
  }
  kept_index_[objects] = static_cast<int>(kept_objects_.size());  // the floor, when a mesh
  kept.floor = scene.floor;
  kept.objects.resize(kept_objects_.size());
  for (size_t k = 0; k < kept_objects_.size(); ++k) {
    kept.objects[k] = scene.objects[kept_objects_[k]];  // reuses the buffers of a like object
  }
  // The search's pairs, renumbered in place: both objects of a collision pair are kept (the pair
  // is their edge), and renumbering keeps the pairs' order, so the kept scene's graph is the one a
  // search of it would give.
  for (FacePair& pair : kept_contacts.faces) {
    pair.object_a = kept_index_[pair.object_a];
    pair.object_b = kept_index_[pair.object_b];
  }
  for (NodePair& pair : kept_contacts.nodes) {
    pair.object_a = kept_index_[pair.object_a];
    pair.object_b = kept_index_[pair.object_b];
  }
  kept_candidates_.clear();
  if (!candidates) return;
  for (const ObjectPair& pair : *candidates) {
    // Out-of-range pairs were rejected by find_interacting_objects.
    const int a = kept_index_[pair.a], b = kept_index_[pair.b];
    if (a >= 0 && b >= 0) kept_candidates_.push_back({a, b});
  }
}

void FreeFlightSplit::keep_rows(const Scene& scene, const Eigen::Ref<const Points>& rows,
                                Points& kept_rows) const {
  Eigen::Index count = 0;
  for (const int o : kept_objects_) count += scene.objects[o].mesh->num_vertices();
  kept_rows.resize(count, 3);
  Eigen::Index row = 0, kept_row = 0;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const Eigen::Index v = scene.objects[o].mesh->num_vertices();
    if (keeps(o)) {
      kept_rows.middleRows(kept_row, v) = rows.middleRows(row, v);
      kept_row += v;
    }
    row += v;
  }
}

void FreeFlightSplit::expand_accelerations(const Scene& scene,
                                           const Eigen::Ref<const Points>& kept_rows,
                                           const Vec3& gravity_step, Points& accelerations) const {
  accelerations.resize(scene.num_nodes(), 3);
  Eigen::Index row = 0, kept_row = 0;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const SceneObject& object = scene.objects[o];
    const Eigen::Index v = object.mesh->num_vertices();
    if (keeps(o)) {
      accelerations.middleRows(row, v) = kept_rows.middleRows(kept_row, v);
      kept_row += v;
    } else if (object.kinematic) {
      accelerations.middleRows(row, v).setZero();
    } else {
      free_flight_accelerations(object, gravity_step, accelerations.middleRows(row, v));
    }
    row += v;
  }
}

}  // namespace fignet
