// The examples' world: native Bullet, or FIGNet when a model file is given on the command line
// (examples/one_line_switch.cpp shows the same switch written out).
#pragma once

#include <btBulletDynamicsCommon.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/io/model_file.h"

struct WorldChoice {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  std::unique_ptr<btDiscreteDynamicsWorld> world;
  btScalar fixed_step = 1.0f / 240.0f;  // native Bullet's usual step; a model dictates its own

  explicit WorldChoice(const char* model_file) {
    if (!model_file) {
      world = std::make_unique<btDiscreteDynamicsWorld>(&dispatcher, &broadphase, &solver,
                                                        &configuration);
    } else {
      auto model = std::make_shared<const fignet::Model>(fignet::load_model(model_file));
      world = std::make_unique<fignet::bullet::FIGNetDynamicsWorld>(&dispatcher, &broadphase,
                                                                    &solver, &configuration, model);
      fixed_step = static_cast<btScalar>(model->config().time_step);
    }
    world->setGravity(btVector3(0, 0, -10));
  }
  std::string name() const { return fixed_step == 1.0f / 240.0f ? "native Bullet" : "FIGNet"; }

  // Two seconds in 48 Hz frames, printing where each labelled body is every half second.
  void run_and_print(const std::vector<std::pair<std::string, const btRigidBody*>>& labelled) {
    std::printf("%s\n", name().c_str());
    for (int frame = 0; frame <= 96; ++frame) {
      if (frame % 24 == 0) {
        std::printf("t = %.1f s:", frame / 48.0);
        for (const auto& [label, body] : labelled) {
          const btVector3 at = body->getCenterOfMassPosition();
          std::printf("  %s (%.2f, %.2f, %.2f)", label.c_str(), at.x(), at.y(), at.z());
        }
        std::printf("\n");
      }
      world->stepSimulation(1.0f / 48.0f, 10, fixed_step);
    }
  }
};
