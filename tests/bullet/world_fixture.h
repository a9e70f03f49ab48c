// A Bullet setup (configuration, dispatcher, broadphase, solver) owning a FIGNetDynamicsWorld and
// the bodies added through it, for tests of the learned world.
#pragma once

#include <memory>
#include <vector>

#include "fignet/bullet/conversions.h"
#include "fignet/bullet/fignet_dynamics_world.h"

namespace fignet::testing {

// A pose from a position and an orientation.
inline Pose at(const Vec3& position,
               const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity()) {
  Pose pose;
  pose.position = position;
  pose.orientation = orientation;
  return pose;
}

// Records what the world asked for and answers with exact free fall.
class RecordingPredictor : public GravityPredictor {
 public:
  using GravityPredictor::GravityPredictor;
  void predict_with_candidates(const Scene& scene, std::span<const ObjectPair> candidates,
                               Points& accelerations) override {
    last_scene = scene;
    last_candidates.assign(candidates.begin(), candidates.end());
    ++calls;
    predict(scene, accelerations);
  }
  void predict_with_search(const Scene& scene, std::span<const ObjectPair> candidates,
                           std::span<const char> interacting, const SceneContacts& contacts,
                           Points& accelerations) override {
    last_interacting.assign(interacting.begin(), interacting.end());
    last_contacts = contacts;
    ++searched_calls;
    predict_with_candidates(scene, candidates, accelerations);
  }
  Scene last_scene;
  std::vector<ObjectPair> last_candidates;
  int calls = 0;  // every prediction
  // Predictions handed the world's contact search, and the last search handed.
  int searched_calls = 0;
  std::vector<char> last_interacting;
  SceneContacts last_contacts;
};

struct WorldFixture {
  explicit WorldFixture(std::unique_ptr<AccelerationPredictor> predictor, GraphConfig graph = {},
                        const bullet::FIGNetWorldOptions& options = {})
      : world(&dispatcher, &broadphase, &solver, &configuration, std::move(predictor), graph, kStep,
              Vec3(0, 0, -10), options) {}
  // The world of a loaded model, as users construct it.
  explicit WorldFixture(std::shared_ptr<const Model> model,
                        const bullet::FIGNetWorldOptions& options = {})
      : world(&dispatcher, &broadphase, &solver, &configuration, std::move(model), options) {}
  ~WorldFixture() {
    for (auto& body : bodies) world.removeRigidBody(body.get());
  }

  // A body of `shape` (owned here) with `mass` (0: static) at `pose`.
  btRigidBody* add(std::unique_ptr<btCollisionShape> shape, double mass, const Pose& pose) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shape->calculateLocalInertia(btScalar(mass), inertia);
    motion_states.push_back(std::make_unique<btDefaultMotionState>(bullet::to_bt(pose)));
    btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), motion_states.back().get(),
                                                  shape.get(), inertia);
    bodies.push_back(std::make_unique<btRigidBody>(info));
    shapes.push_back(std::move(shape));
    world.addRigidBody(bodies.back().get());
    return bodies.back().get();
  }
  void step(int steps = 1) {
    for (int i = 0; i < steps; ++i) world.stepSimulation(btScalar(kStep), 1, btScalar(kStep));
  }

  static constexpr double kStep = 1.0 / 48.0;
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  bullet::FIGNetDynamicsWorld world;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
};

inline std::unique_ptr<RecordingPredictor> recording_predictor() {
  return std::make_unique<RecordingPredictor>(Vec3(0, 0, -10), 1.0 / 48.0);
}

}  // namespace fignet::testing
