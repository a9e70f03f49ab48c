// Bullet's "hello world" (boxes and a sphere falling onto a ground plane), run by native Bullet
// or, with a model file, by FIGNet. The only FIGNet-specific lines are the marked ones: the
// world's construction and the fixed time step the model was trained with.
//
//   build/release/examples/example_one_line_switch                      # native Bullet
//   build/release/examples/example_one_line_switch models/movi-a-small.h5   # FIGNet
#include <btBulletDynamicsCommon.h>

#include <cstdio>
#include <memory>
#include <vector>

#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/error.h"
#include "fignet/io/model_file.h"

int main(int argc, char** argv) try {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;

  std::unique_ptr<btDiscreteDynamicsWorld> world;
  btScalar fixed_step = 1.0f / 60.0f;
  if (argc < 2) {
    world = std::make_unique<btDiscreteDynamicsWorld>(&dispatcher, &broadphase, &solver,
                                                      &configuration);
  } else {
    auto model = std::make_shared<const fignet::Model>(fignet::load_model(argv[1]));
    // FIGNet: the one line that changes, and the model's time step.
    world = std::make_unique<fignet::bullet::FIGNetDynamicsWorld>(&dispatcher, &broadphase, &solver,
                                                                  &configuration, model);
    fixed_step = static_cast<btScalar>(model->config().time_step);
  }
  world->setGravity(btVector3(0, 0, -10));

  // Everything below is plain Bullet.
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  auto add = [&](std::unique_ptr<btCollisionShape> shape, btScalar mass, const btVector3& at) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shape->calculateLocalInertia(mass, inertia);
    motion_states.push_back(
        std::make_unique<btDefaultMotionState>(btTransform(btQuaternion::getIdentity(), at)));
    bodies.push_back(std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(
        mass, motion_states.back().get(), shape.get(), inertia)));
    shapes.push_back(std::move(shape));
    world->addRigidBody(bodies.back().get());
    return bodies.back().get();
  };
  add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0, btVector3(0, 0, 0));
  btRigidBody* box = add(std::make_unique<btBoxShape>(btVector3(1, 1, 1)), 2.7f, {0, 0, 3});
  add(std::make_unique<btBoxShape>(btVector3(0.7f, 0.7f, 0.7f)), 1.1f, {0.5f, 0.3f, 6});
  add(std::make_unique<btSphereShape>(0.7f), 1.1f, {-0.4f, 0.2f, 9});
  box->setLinearVelocity(btVector3(1, 0, 0));

  for (int frame = 0; frame <= 96; ++frame) {
    if (frame % 12 == 0) {
      std::printf("t = %.2f s:", frame / 48.0);
      for (size_t i = 1; i < bodies.size(); ++i) {
        btTransform t;
        bodies[i]->getMotionState()->getWorldTransform(t);
        std::printf("  (%.2f, %.2f, %.2f)", t.getOrigin().x(), t.getOrigin().y(),
                    t.getOrigin().z());
      }
      std::printf("\n");
    }
    world->stepSimulation(1.0f / 48.0f, 10, fixed_step);
  }
  for (auto& body : bodies) world->removeRigidBody(body.get());
  return 0;
} catch (const fignet::Error& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
