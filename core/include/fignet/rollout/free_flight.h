// Free flight: bodies that touch nothing move by gravity alone, outside the network. The Bullet
// world has always moved them so; a model trained with GraphConfig::omit_free_flight leaves them
// out of its graphs in training too, and its predictor moves them so wherever it runs.
#pragma once

#include <span>
#include <vector>

#include "fignet/graph/graph_builder.h"
#include "fignet/graph/scene.h"

namespace fignet {

// The pose after `current` of a body that touches nothing: its centre keeps its last step and
// falls by gravity·dt² more (x_{t+1} = 2x_t − x_{t−1} + g·dt², exact for constant acceleration),
// and it turns by its last step's rotation again.
Pose free_flight_pose(const Pose& previous, const Pose& current, const Vec3& gravity_step);

// Writes into `rows` (one per node of the dynamic `object`, as AccelerationPredictor::predict
// writes them) the accelerations x^{t+1} − 2x^t + x^{t−1} that carry its nodes to its free-flight
// pose, the last two poses fitted to its last two node positions (rollout's rigid fit then
// recovers that pose).
void free_flight_accelerations(const SceneObject& object, const Vec3& gravity_step,
                               Eigen::Ref<Points> rows);

// A scene without its objects that have no collision edge (GraphConfig::omit_free_flight): which
// objects the graph builder would connect to another, a copy of the scene with only those, and
// the ways between per-node rows of the copy and of the whole scene.
class FreeFlightSplit {
 public:
  // Finds the objects of `scene` with a collision edge (GraphBuilder::find_interacting_objects,
  // with the caller's candidate pairs when given) and copies them, in order, into `kept` (whose
  // buffers are reused); the floor stays. The search's collision pairs, renumbered, go into
  // `kept_contacts`: GraphBuilder::build_with_contacts builds `kept` from them without searching
  // again. Candidate pairs are renumbered into kept_candidates().
  void split(GraphBuilder& builder, const Scene& scene,
             const std::span<const ObjectPair>* candidates, Scene& kept,
             SceneContacts& kept_contacts);
  // As split(), from the search of `scene` the caller made already (find_interacting_objects's
  // flags and collision pairs, with the same graph config and candidates), so that it is not
  // made twice. Throws ConfigError when the flags do not match the scene's objects.
  void split_searched(const Scene& scene, std::span<const char> interacting,
                      const SceneContacts& contacts, const std::span<const ObjectPair>* candidates,
                      Scene& kept, SceneContacts& kept_contacts);
  // For each object of the kept scene, its index in the scene split last.
  std::span<const int> kept_objects() const { return kept_objects_; }
  std::span<const ObjectPair> kept_candidates() const { return kept_candidates_; }
  // Whether object o of the scene split last is in the kept scene.
  bool keeps(size_t o) const { return kept_index_[o] >= 0; }

  // The rows of the kept objects' nodes among per-node rows of the whole scene.
  void keep_rows(const Scene& scene, const Eigen::Ref<const Points>& rows, Points& kept_rows) const;
  // Per-node accelerations of the whole scene from those of the kept scene (one row per node of
  // it): the kept objects' rows copied, the others' their free-flight accelerations (zero for
  // kinematic ones, whose rows callers ignore).
  void expand_accelerations(const Scene& scene, const Eigen::Ref<const Points>& kept_rows,
                            const Vec3& gravity_step, Points& accelerations) const;

 private:
  // The kept scene, contacts and candidates from interacting_ and the search's pairs.
  void keep(const Scene& scene, const std::span<const ObjectPair>* candidates, Scene& kept,
            SceneContacts& kept_contacts);

  std::vector<char> interacting_;
  std::vector<int> kept_index_, kept_objects_;
  std::vector<ObjectPair> kept_candidates_;
};

}  // namespace fignet
