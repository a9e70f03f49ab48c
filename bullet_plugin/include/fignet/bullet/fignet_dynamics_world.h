// FIGNetDynamicsWorld: a btDiscreteDynamicsWorld whose dynamic bodies are moved by a learned
// FIGNet model instead of Bullet's constraint solver. Switching a program is one line:
//
//   btDiscreteDynamicsWorld* world = new btDiscreteDynamicsWorld(dispatcher, broadphase, solver,
//   config); btDiscreteDynamicsWorld* world = new fignet::bullet::FIGNetDynamicsWorld(dispatcher,
//   broadphase, solver, config, model);
//
// and stepping with the model's time step: world->stepSimulation(dt, maxSubSteps, 1.0 / 48).
// Bodies, shapes, motion states, tick callbacks, sleeping, collision filtering and debug drawing
// work as in Bullet; see docs/bullet-world.md for what differs.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <memory>

#include "fignet/graph/config.h"
#include "fignet/model/model.h"
#include "fignet/rollout/predictor.h"

namespace fignet::bullet {

struct FIGNetWorldOptions {
  // stepSimulation's fixed time step must equal the model's training step (anything else
  // changes what the network's velocities mean); true accepts any step, at the user's risk.
  bool allow_time_step_mismatch = false;
  // Bodies must fall with the model's training gravity; true accepts another.
  bool allow_gravity_mismatch = false;
  // Broadphase boxes grow by d_c plus the distance a body moved in its last step, so a fast body
  // still finds what it is about to hit (false: d_c only, as in training).
  bool grow_search_by_travel = true;
  // The tunnelling guard: a body whose predicted step is longer than the collision radius has a
  // sphere deep inside it swept along the step (Bullet's CCD rule); if that core would cross a
  // surface, the body stops where its shape touches it and keeps only its velocity along it.
  // Contacts and shallower penetrations, at any speed, are the model's.
  bool sweep_guard = true;
  // Free flight: a body with no collision edge this step (nothing within d_c, the floor
  // included) moves exactly under gravity and its applied forces (constant angular velocity),
  // without the network, which runs only on the bodies in contact and what they touch; its cost
  // follows the contacting part of the scene. false: every awake body goes through the network.
  bool free_flight = true;
  // A body's history is seeded from its velocities when it enters the world, wakes, or the user
  // moves it or sets its velocity. true: one in free flight (judged by its broadphase partners:
  // floor planes more than d_c below it, dynamic bodies whose bounding spheres are more than d_c
  // from its own) is seeded as falling along its gravity's parabola, as bodies in the training
  // data were, so its first steps neither fall ½·g·dt² too far nor keep a spurious g·dt/2 of
  // downward velocity. A body that may be supported is seeded moving straight. false: every
  // body is seeded moving straight.
  bool seed_falling = true;
  // Islands whose bodies all want to sleep (Bullet's thresholds and deactivation time) sleep and
  // wake together when touched, as in Bullet. false: bodies never sleep.
  bool sleeping = true;
  // The penetration guard: after the learned step, a body that penetrates static geometry (planes,
  // triangle meshes, convex shapes) deeper than penetration_tolerance is moved out along the
  // contact normal to the tolerance and loses the inward part of its velocity, as Bullet's
  // split-impulse recovery does for its own solver: a model that sinks a body slowly has it held
  // there, without jumps. Depths are Bullet's contact distances (collision margins included).
  bool penetration_guard = true;
  double penetration_tolerance = 0.005;  // metres
  // The rest guard, Coulomb's static friction under gravity. A body stays where it is when
  //  - no force but gravity was applied to it this step and nothing that moves touches it;
  //  - it is slower than friction stops in one step: |v| and |ω|·radius <= μ·|g|·dt, μ Bullet's
  //    combined friction with what lies below it;
  //  - it stands: its centre of mass over its support (the contact points within
  //    rest_contact_distance, on the meshes the network sees, of static geometry and of bodies
  //    held this step below it), and gravity within the friction cone of the support's mean
  //    normal.
  // So stacks at rest stay, and a body on a slope steeper than its friction, tipping over an
  // edge, or touched by a moving body is left to the model. It replaces the network's small
  // creep at rest, which integrates to metres over thousands of steps; Bullet's sleeping then
  // takes over. false: the model moves resting bodies.
  bool rest_guard = true;
  double rest_contact_distance = 0.005;  // metres
  // The energy guard: contact between passive rigid bodies only takes mechanical energy away
  // (restitution at most 1, friction), so an island of bodies the network moved whose step
  // gains kinetic plus potential energy beyond energy_tolerance of its kinetic energy (and a
  // millimetre's lift per body) has its bodies' steps shortened, all by one factor, until it does
  // not. A model outside its data (shapes, speeds, materials) otherwise throws bodies about.
  // Islands touched by a kinematic body or a force other than gravity are left alone.
  bool energy_guard = true;
  double energy_tolerance = 0.1;  // fraction of the island's kinetic energy before the step
  // The node budget: a body's mesh with more vertices than this is simplified (meshoptimizer,
  // once per shape) within simplify_tolerance of its largest side before it enters the graph, so
  // a 20,000-vertex mesh costs about what the model's own meshes cost; the tolerance keeps the
  // shape and may stop above the budget. Bullet's collision shape is untouched.
  // kModelResolution: the finest mesh the model was trained on (ModelConfig::mesh_vertices; 64 for
  // MOVi-A), or kDefaultGraphVertices for a model file that predates it or a bare predictor.
  // 0: every mesh as it is.
  static constexpr int kModelResolution = -1;
  static constexpr int kDefaultGraphVertices = 1000;  // MOVi's finest shape has 960
  int max_graph_vertices = kModelResolution;
  // 2 % of the largest side: finer than the model's own meshes are faceted (MOVi's 64-vertex
  // sphere deviates 3.8 % from the sphere); a 20,000-vertex sphere keeps about 100 vertices.
  double simplify_tolerance = 0.02;

  // The network alone on every awake body, as `fignet eval` rolls out and the paper measures: no
  // free flight, no sleeping, no penetration, rest or energy guard (the sweep guard is kept).
  static FIGNetWorldOptions network_alone() {
    FIGNetWorldOptions options;
    options.free_flight = false;
    options.sleeping = false;
    options.penetration_guard = false;
    options.rest_guard = false;
    options.energy_guard = false;
    return options;
  }
  // Threads for the network's matrix products, or with turns > 1 for the turned copies, one per
  // thread (see PredictionOptions; 0: every core). One keeps a step from stalling behind the host
  // program's own threads.
  int threads = 1;
  // Predictions averaged over the scene turned by k/turns of a turn about the vertical (see
  // PredictionOptions::turns): cancels the model's own sideways push on resting bodies, at
  // `turns` times the network's cost. 1: off. Only for worlds built from a model.
  int turns = 1;
  // Also average over the scene seen in a mirror, at each turn (PredictionOptions::mirror): at
  // 2·turns times the network's cost. Only for worlds built from a model.
  bool mirror = false;
  // The network sees the scene's masses times the common factor that brings them within its
  // training data's (PredictionOptions::fit_masses; only for worlds built from a model).
  bool fit_masses = true;
};

// What the last internal step simulated and what it cost.
struct FIGNetStepStats {
  int simulated_bodies = 0;    // awake dynamic bodies predicted by the model
  int free_flight_bodies = 0;  // awake dynamic bodies moved without it (no collision edge)
  int sleeping_bodies = 0;     // dynamic bodies skipped because Bullet put them to sleep
  int kinematic_objects = 0;   // static, kinematic and held bodies in contact range, no floor
  int candidate_pairs = 0;     // broadphase pairs handed to the face-pair search
  int face_edges = 0;          // face–face edges of the graph
  int mesh_nodes = 0;          // mesh vertices in the network's graph (after the node budget)
  int guarded_bodies = 0;      // bodies stopped by the tunnelling guard
  int recovered_bodies = 0;    // bodies moved out of static geometry by the penetration guard
  int rested_bodies = 0;       // awake bodies the rest guard kept still, without the network
  int energy_bodies = 0;       // bodies whose steps the energy guard shortened
  // Simulated bodies whose friction or restitution lie outside the model's training data's
  // (ModelConfig::friction, restitution), and whether the floor in contact range does: there
  // the model guesses. Always 0 and false for a model that does not record its data's materials.
  int unfamiliar_bodies = 0;
  bool unfamiliar_floor = false;
  double prepare_seconds = 0;     // broadphase, islands, meshes and histories
  double predict_seconds = 0;     // graph and network
  double write_back_seconds = 0;  // rigid fits and Bullet state
};

class FIGNetDynamicsWorld : public btDiscreteDynamicsWorld {
 public:
  // Constructed like btDiscreteDynamicsWorld plus a loaded model (shared, immutable).
  FIGNetDynamicsWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                      btConstraintSolver* solver, btCollisionConfiguration* configuration,
                      std::shared_ptr<const Model> model, const FIGNetWorldOptions& options = {});
  // Any predictor (a stand-in for tests and baselines) with the setting it assumes.
  FIGNetDynamicsWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                      btConstraintSolver* solver, btCollisionConfiguration* configuration,
                      std::unique_ptr<AccelerationPredictor> predictor, const GraphConfig& graph,
                      double time_step, const Vec3& gravity,
                      const FIGNetWorldOptions& options = {});
  ~FIGNetDynamicsWorld() override;

  void removeRigidBody(btRigidBody* body) override;
  void removeCollisionObject(btCollisionObject* object) override;
  // Bullet's drawing, plus each face–face edge of the last step as a line between face centres.
  void debugDrawWorld() override;

  // The triangle mesh (in the shape's local frame, current local scaling) that stands for
  // `shape` in the graph, instead of the one converted from the shape. A convex hull built from a
  // mesh has lost the mesh's triangulation and inner vertices, and the model was trained on the
  // mesh: RigidBodies registers each spec's mesh this way. Throws ConfigError when the mesh does
  // not fit the shape's bounding box (a wrong frame or scale).
  void set_shape_mesh(const btCollisionShape& shape, std::shared_ptr<const TriangleMesh> mesh);

  double model_time_step() const;
  const FIGNetStepStats& last_step_stats() const;
  // The pose the world keeps for a moving body in double precision (Bullet's transforms are
  // single precision): what the next step starts from. Other objects: their Bullet transform.
  Pose precise_pose(const btCollisionObject& object) const;

 protected:
  void internalSingleStepSimulation(btScalar time_step) override;
  // Bullet's AABB update with every box grown by the collision radius (and travel).
  void updateAabbs() override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fignet::bullet
