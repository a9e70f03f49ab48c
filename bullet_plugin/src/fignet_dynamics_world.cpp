#include "fignet/bullet/fignet_dynamics_world.h"

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <LinearMath/btTransformUtil.h>
#include <fmt/format.h>

#include <chrono>
#include <numeric>
#include <unordered_map>

#include "fignet/bullet/conversions.h"
#include "fignet/bullet/shape_mesh.h"
#include "fignet/error.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/rollout/rollout.h"

namespace fignet::bullet {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool is_dynamic(const btCollisionObject* object) {
  return btRigidBody::upcast(object) && !object->isStaticOrKinematicObject();
}

// A static plane whose world normal is +z: the floor the model was trained with.
std::optional<Floor> as_floor(const btCollisionObject& object) {
  if (object.getCollisionShape()->getShapeType() != STATIC_PLANE_PROXYTYPE) return std::nullopt;
  const auto& plane = static_cast<const btStaticPlaneShape&>(*object.getCollisionShape());
  const btTransform& t = object.getWorldTransform();
  const btVector3 normal = t.getBasis() * plane.getPlaneNormal();
  if (normal.z() < 1.0 - 1e-6) return std::nullopt;
  const btVector3 point = t * (plane.getPlaneNormal() * plane.getPlaneConstant());
  return Floor{point.z(), {0.0, object.getFriction(), object.getRestitution()}};
}

// Poses h, h−1, …, 0 steps back from `current`, moving with constant velocities (oldest first).
std::vector<Pose> seed_history(const Pose& current, const Vec3& linear, const Vec3& angular,
                               int history, double dt) {
  std::vector<Pose> poses(history + 1);
  for (int k = 0; k <= history; ++k) {
    const double tau = (k - history) * dt;  // <= 0
    poses[k].position = current.position + tau * linear;
    const Vec3 angle = tau * angular;
    poses[k].orientation =
        angle.norm() > 0
            ? (Eigen::AngleAxisd(angle.norm(), angle.normalized()) * current.orientation)
                  .normalized()
            : current.orientation;
  }
  return poses;
}

}  // namespace

struct FIGNetDynamicsWorld::Impl {
  // What the world remembers of a moving (dynamic or kinematic) body between steps.
  struct BodyState {
    std::shared_ptr<const TriangleMesh> mesh;
    std::vector<Pose> poses;  // h + 1 poses one model step apart, oldest first
    btTransform written;      // what the last step wrote, to notice the user's changes
    btVector3 written_linear, written_angular;
    bool valid = false;
    double travel = 0.0;  // how far the body's points moved in the last step (bound)
    double radius = 0.0;  // of the mesh's bounding sphere about the centre of mass
  };

  FIGNetWorldOptions options;
  std::unique_ptr<AccelerationPredictor> predictor;
  GraphConfig graph;
  double time_step;
  Vec3 gravity;
  ShapeMeshCache shapes;
  std::unordered_map<const btCollisionObject*, BodyState> states;
  FIGNetStepStats stats;
  std::vector<std::pair<Vec3, Vec3>> face_lines;  // last step's face–face edges, for drawing

  // Per-step scratch.
  Scene scene;
  std::vector<btRigidBody*> dynamic_bodies;  // all dynamic rigid bodies of the world
  std::vector<btRigidBody*> simulated;       // scene.objects[0 … simulated.size()) in order
  std::unordered_map<const btCollisionObject*, int> scene_index;
  std::unordered_map<const btCollisionObject*, int> dynamic_index;  // into dynamic_bodies
  std::vector<std::unique_ptr<TriangleMesh>> pieces;  // static-mesh triangles near bodies
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;
  std::vector<ObjectPair> candidates;
  std::vector<std::pair<btCollisionObject*, btCollisionObject*>> pairs;
  std::vector<int> island;
  StepWorkspace workspace;
  std::vector<Pose> next;

  int find(int i) {
    while (island[i] != i) i = island[i] = island[island[i]];
    return i;
  }

  // The awake dynamic bodies' broadphase pairs (filtering respected by the broadphase and the
  // dispatcher), then islands: an island whose bodies all want to sleep sleeps; one that touches
  // an awake body wakes (Bullet's rules, with broadphase contact standing in for manifolds).
  void collect_pairs_and_islands(btDiscreteDynamicsWorld& world) {
    pairs.clear();
    btBroadphasePairArray& array = world.getPairCache()->getOverlappingPairArray();
    for (int i = 0; i < array.size(); ++i) {
      auto* a = static_cast<btCollisionObject*>(array[i].m_pProxy0->m_clientObject);
      auto* b = static_cast<btCollisionObject*>(array[i].m_pProxy1->m_clientObject);
      if (!btRigidBody::upcast(a) || !btRigidBody::upcast(b)) continue;  // ghosts, triggers
      if (!a->hasContactResponse() || !b->hasContactResponse()) continue;
      if (!is_dynamic(a) && !is_dynamic(b)) continue;
      if (!world.getDispatcher()->needsCollision(a, b)) continue;
      pairs.emplace_back(a, b);
    }
    dynamic_bodies.clear();
    for (int i = 0; i < world.getNumCollisionObjects(); ++i) {
      btCollisionObject* object = world.getCollisionObjectArray()[i];
      if (is_dynamic(object)) dynamic_bodies.push_back(btRigidBody::upcast(object));
    }
    std::unordered_map<const btCollisionObject*, int>& index = dynamic_index;
    index.clear();
    for (size_t i = 0; i < dynamic_bodies.size(); ++i) index[dynamic_bodies[i]] = int(i);
    island.resize(dynamic_bodies.size());
    std::iota(island.begin(), island.end(), 0);
    for (const auto& [a, b] : pairs) {
      if (is_dynamic(a) && is_dynamic(b)) island[find(index[a])] = find(index[b]);
    }
    // Per island root: any awake body, any asleep, every awake one ready to sleep.
    std::vector<char> awake(island.size(), 0), asleep(island.size(), 0), ready(island.size(), 1);
    for (size_t i = 0; i < dynamic_bodies.size(); ++i) {
      btRigidBody* body = dynamic_bodies[i];
      const int root = find(int(i));
      if (body->getActivationState() == DISABLE_SIMULATION) continue;
      if (body->isActive()) {
        awake[root] = 1;
        ready[root] = ready[root] && body->wantsSleeping();
      } else {
        asleep[root] = 1;
      }
    }
    for (size_t i = 0; i < dynamic_bodies.size(); ++i) {
      btRigidBody* body = dynamic_bodies[i];
      const int root = find(int(i));
      if (body->getActivationState() == DISABLE_SIMULATION || !awake[root]) continue;
      if (asleep[root] && !body->isActive()) {
        body->activate(true);
        states[body].valid = false;
      } else if (!asleep[root] && ready[root] && body->isActive()) {
        body->setActivationState(ISLAND_SLEEPING);
        body->setLinearVelocity(btVector3(0, 0, 0));
        body->setAngularVelocity(btVector3(0, 0, 0));
        states[body].valid = false;
      }
    }
  }

  // The body's state, its history reseeded from its current velocities when it is new, woke up,
  // or the user moved it or changed its velocity since the last step.
  BodyState& state_of(btRigidBody& body) {
    BodyState& state = states[&body];
    if (!state.mesh) {
      state.mesh = shapes.mesh_of(*body.getCollisionShape());
      state.radius = state.mesh->vertices().rowwise().norm().maxCoeff();
    }
    const bool unchanged = state.valid && body.getWorldTransform() == state.written &&
                           body.getLinearVelocity() == state.written_linear &&
                           body.getAngularVelocity() == state.written_angular;
    if (!unchanged) {
      state.poses =
          seed_history(from_bt(body.getWorldTransform()), from_bt(body.getLinearVelocity()),
                       from_bt(body.getAngularVelocity()), graph.history, time_step);
      state.valid = true;
    }
    return state;
  }

  int add_object(const TriangleMesh& mesh, std::span<const Pose> poses,
                 const std::optional<Pose>& next_pose, const StaticProperties& properties) {
    scene.objects.emplace_back();
    SceneObject& object = scene.objects.back();
    object.mesh = &mesh;
    object.properties = properties;
    object.kinematic = next_pose.has_value();
    set_pose_history(object, poses, next_pose);
    return static_cast<int>(scene.objects.size()) - 1;
  }

  // A static or kinematic partner of dynamic scene object `partner`: a floor candidate, a piece
  // of a static triangle mesh near the partner, or the whole body as a kinematic object.
  void add_obstacle(btCollisionObject& object, int partner, const btCollisionObject& dynamic) {
    if (graph.floor != FloorModel::kNone && as_floor(object)) {
      candidates.push_back({partner, -1});  // the floor's index is known once objects are
      return;
    }
    const StaticProperties properties{0.0, object.getFriction(), object.getRestitution()};
    const Pose pose = from_bt(object.getWorldTransform());
    const btCollisionShape* shape = object.getCollisionShape();
    if (shape->isConcave()) {
      // Only the triangles within the dynamic body's grown box, in the mesh's frame.
      btVector3 lower, upper;
      dynamic.getCollisionShape()->getAabb(
          object.getWorldTransform().inverse() * dynamic.getWorldTransform(), lower, upper);
      const btScalar grow = btScalar(graph.collision_radius + states[&dynamic].travel);
      lower -= btVector3(grow, grow, grow), upper += btVector3(grow, grow, grow);
      auto piece =
          concave_triangles_in_box(static_cast<const btConcaveShape&>(*shape), lower, upper);
      if (!piece) return;
      pieces.push_back(std::move(piece));
      const std::vector<Pose> poses(graph.history + 1, pose);
      candidates.push_back({partner, add_object(*pieces.back(), poses, pose, properties)});
      return;
    }
    auto found = scene_index.find(&object);
    if (found == scene_index.end()) {
      std::vector<Pose> poses(graph.history + 1, pose);
      Pose next = pose;
      if (object.isKinematicObject()) {
        // Bullet has already moved a kinematic body to its motion state's target: that is its
        // next pose; its history was recorded by earlier steps.
        BodyState& state = states[&object];
        if (!state.valid) {
          state.poses = seed_history(pose, Vec3::Zero(), Vec3::Zero(), graph.history, time_step);
          state.valid = true;
        }
        poses = state.poses;
      }
      meshes.push_back(shapes.mesh_of(*shape));
      found =
          scene_index.emplace(&object, add_object(*meshes.back(), poses, next, properties)).first;
    }
    candidates.push_back({partner, found->second});
  }

  void build_scene() {
    scene.objects.clear();
    scene.floor.reset();
    simulated.clear();
    scene_index.clear();
    pieces.clear();
    meshes.clear();
    candidates.clear();
    for (btRigidBody* body : dynamic_bodies) {
      if (!body->isActive()) continue;
      BodyState& state = state_of(*body);
      scene_index[body] =
          add_object(*state.mesh, state.poses, std::nullopt,
                     {1.0 / body->getInvMass(), body->getFriction(), body->getRestitution()});
      simulated.push_back(body);
    }
    for (const auto& [a, b] : pairs) {
      const bool a_moves = is_dynamic(a) && a->isActive(), b_moves = is_dynamic(b) && b->isActive();
      if (a_moves && b_moves) {
        candidates.push_back(
            {std::min(scene_index[a], scene_index[b]), std::max(scene_index[a], scene_index[b])});
      } else if (a_moves && !is_dynamic(b)) {
        add_obstacle(*b, scene_index[a], *a);
      } else if (b_moves && !is_dynamic(a)) {
        add_obstacle(*a, scene_index[b], *b);
      }
    }
    // The floor: the model's own floor object, paired where the broadphase says.
    const int floor_index = static_cast<int>(scene.objects.size());
    for (ObjectPair& pair : candidates) {
      if (pair.b == -1) pair.b = floor_index;
    }
    for (const auto& [a, b] : pairs) {
      for (const btCollisionObject* object : {a, b}) {
        if (!scene.floor && graph.floor != FloorModel::kNone) scene.floor = as_floor(*object);
      }
    }
    std::sort(candidates.begin(), candidates.end(), [](const ObjectPair& x, const ObjectPair& y) {
      return std::tie(x.a, x.b) < std::tie(y.a, y.b);
    });
    candidates.erase(std::unique(candidates.begin(), candidates.end(),
                                 [](const ObjectPair& x, const ObjectPair& y) {
                                   return x.a == y.a && x.b == y.b;
                                 }),
                     candidates.end());
  }

  // The tunnelling guard. A step longer than the collision radius can carry a body past a surface
  // that was never within the graph's reach; such a step is swept with the body's convex shape
  // (or, for compounds, a sphere inside it) and, if it would cross a surface it moves against,
  // the body stops where it touches, as Bullet's CCD stops a body.
  void guard_fast_bodies(btCollisionWorld& world) {
    if (!options.sweep_guard) return;
    for (size_t i = 0; i < simulated.size(); ++i) {
      btRigidBody& body = *simulated[i];
      const Pose& current = states[&body].poses.back();
      Pose& next_pose = next[i];
      const Vec3 motion = next_pose.position - current.position;
      if (motion.norm() <= graph.collision_radius) continue;
      const btCollisionShape* shape = body.getCollisionShape();
      std::unique_ptr<btSphereShape> inner;
      const btConvexShape* swept = nullptr;
      if (shape->isConvex()) {
        swept = static_cast<const btConvexShape*>(shape);
      } else {
        btVector3 low, high;
        shape->getAabb(btTransform::getIdentity(), low, high);
        const btVector3 size = high - low;
        inner = std::make_unique<btSphereShape>(0.25f * size[size.minAxis()]);
        swept = inner.get();
      }
      Pose from = current, to = current;
      to.position = next_pose.position;
      SweepCallback hit(&body, to_bt(from.position), to_bt(to.position));
      world.convexSweepTest(swept, to_bt(from), to_bt(to), hit);
      if (!hit.hasHit()) continue;
      const double fraction = hit.m_closestHitFraction;
      next_pose.position = current.position + fraction * motion;
      next_pose.orientation = current.orientation.slerp(fraction, next_pose.orientation);
      ++stats.guarded_bodies;
    }
  }

  // Closest surface the swept body moves against (Bullet's CCD rule: not itself, only objects
  // with contact response, and only hits whose normal opposes the motion, so sliding along a
  // surface it rests on is not a hit).
  struct SweepCallback : btCollisionWorld::ClosestConvexResultCallback {
    SweepCallback(const btCollisionObject* self, const btVector3& from, const btVector3& to)
        : ClosestConvexResultCallback(from, to), self_(self) {
      m_collisionFilterGroup = self->getBroadphaseHandle()->m_collisionFilterGroup;
      m_collisionFilterMask = self->getBroadphaseHandle()->m_collisionFilterMask;
    }
    btScalar addSingleResult(btCollisionWorld::LocalConvexResult& result,
                             bool normal_in_world) override {
      if (result.m_hitCollisionObject == self_) return 1;
      if (!result.m_hitCollisionObject->hasContactResponse()) return 1;
      const btVector3 normal = normal_in_world
                                   ? result.m_hitNormalLocal
                                   : result.m_hitCollisionObject->getWorldTransform().getBasis() *
                                         result.m_hitNormalLocal;
      if (normal.dot(m_convexToWorld - m_convexFromWorld) >= 0) return 1;
      return ClosestConvexResultCallback::addSingleResult(result, normal_in_world);
    }
    const btCollisionObject* self_;
  };

  // New poses, velocities and interpolation state of the simulated bodies.
  void write_back() {
    for (size_t i = 0; i < simulated.size(); ++i) {
      btRigidBody& body = *simulated[i];
      BodyState& state = states[&body];
      const Pose& current = state.poses.back();
      const Pose& next_pose = next[i];
      const Vec3 linear = (next_pose.position - current.position) / time_step;
      const Eigen::AngleAxisd turn(next_pose.orientation * current.orientation.conjugate());
      const Vec3 angular = turn.axis() * (turn.angle() / time_step);
      body.setLinearVelocity(to_bt(linear));
      body.setAngularVelocity(to_bt(angular));
      body.proceedToTransform(to_bt(next_pose));  // also the interpolation transform/velocities
      std::rotate(state.poses.begin(), state.poses.begin() + 1, state.poses.end());
      state.poses.back() = next_pose;
      state.written = body.getWorldTransform();
      state.written_linear = body.getLinearVelocity();
      state.written_angular = body.getAngularVelocity();
      state.travel =
          (next_pose.position - current.position).norm() + std::abs(turn.angle()) * state.radius;
      body.updateDeactivation(btScalar(time_step));
    }
  }

  // Kinematic bodies' histories advance every step, touched or not.
  void record_kinematic_poses(btDiscreteDynamicsWorld& world) {
    for (int i = 0; i < world.getNumCollisionObjects(); ++i) {
      const btCollisionObject* object = world.getCollisionObjectArray()[i];
      if (!object->isKinematicObject()) continue;
      BodyState& state = states[object];
      const Pose pose = from_bt(object->getWorldTransform());
      if (!state.valid) {
        state.poses = seed_history(pose, Vec3::Zero(), Vec3::Zero(), graph.history, time_step);
        state.valid = true;
      } else {
        std::rotate(state.poses.begin(), state.poses.begin() + 1, state.poses.end());
        state.poses.back() = pose;
      }
    }
  }

  void record_face_lines() {
    face_lines.clear();
    const auto* model = dynamic_cast<const ModelPredictor*>(predictor.get());
    if (!model) return;
    for (const FacePair& pair : model->builder().face_pairs())
      face_lines.emplace_back(pair.point_a, pair.point_b);
  }
};

FIGNetDynamicsWorld::FIGNetDynamicsWorld(btDispatcher* dispatcher,
                                         btBroadphaseInterface* broadphase,
                                         btConstraintSolver* solver,
                                         btCollisionConfiguration* configuration,
                                         std::shared_ptr<const Model> model,
                                         const FIGNetWorldOptions& options)
    : FIGNetDynamicsWorld(dispatcher, broadphase, solver, configuration,
                          std::make_unique<ModelPredictor>(model, options.threads),
                          model->config().graph, model->config().time_step, model->config().gravity,
                          options) {}

FIGNetDynamicsWorld::FIGNetDynamicsWorld(btDispatcher* dispatcher,
                                         btBroadphaseInterface* broadphase,
                                         btConstraintSolver* solver,
                                         btCollisionConfiguration* configuration,
                                         std::unique_ptr<AccelerationPredictor> predictor,
                                         const GraphConfig& graph, double time_step,
                                         const Vec3& gravity, const FIGNetWorldOptions& options)
    : btDiscreteDynamicsWorld(dispatcher, broadphase, solver, configuration),
      impl_(std::make_unique<Impl>()) {
  if (!predictor) throw ConfigError("FIGNetDynamicsWorld: no predictor");
  if (predictor->history() != graph.history) {
    throw ConfigError(
        fmt::format("FIGNetDynamicsWorld: the predictor needs {} past steps, the "
                    "graph config {}",
                    predictor->history(), graph.history));
  }
  graph.validate();
  impl_->options = options;
  impl_->predictor = std::move(predictor);
  impl_->graph = graph;
  impl_->time_step = time_step;
  impl_->gravity = gravity;
  setGravity(to_bt(gravity));
}

FIGNetDynamicsWorld::~FIGNetDynamicsWorld() = default;

double FIGNetDynamicsWorld::model_time_step() const {
  return impl_->time_step;
}
void FIGNetDynamicsWorld::set_shape_mesh(const btCollisionShape& shape,
                                         std::shared_ptr<const TriangleMesh> mesh) {
  if (!mesh) throw ConfigError("FIGNetDynamicsWorld::set_shape_mesh: no mesh");
  // The mesh must lie in the shape's box, give or take the margin and a 5 % tolerance.
  btVector3 low, high;
  shape.getAabb(btTransform::getIdentity(), low, high);
  const Vec3 lo = from_bt(low), hi = from_bt(high);
  const double slack = 0.05 * (hi - lo).norm() + shape.getMargin();
  const Points& v = mesh->vertices();
  const Vec3 mesh_lo = v.colwise().minCoeff().transpose(),
             mesh_hi = v.colwise().maxCoeff().transpose();
  if ((mesh_lo - lo).minCoeff() < -slack || (hi - mesh_hi).minCoeff() < -slack) {
    throw ConfigError(fmt::format(
        "FIGNetDynamicsWorld::set_shape_mesh: mesh '{}' spans ({:.3g}, {:.3g}, {:.3g}) to ({:.3g}, "
        "{:.3g}, {:.3g}), outside its {} shape's box ({:.3g}, {:.3g}, {:.3g}) to ({:.3g}, {:.3g}, "
        "{:.3g}); is it in the shape's frame and scale?",
        mesh->name(), mesh_lo.x(), mesh_lo.y(), mesh_lo.z(), mesh_hi.x(), mesh_hi.y(), mesh_hi.z(),
        shape.getName(), lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z()));
  }
  impl_->shapes.set_mesh(shape, std::move(mesh));
  // Bodies already seen with this shape pick the mesh up at their next step.
  for (auto& [body, state] : impl_->states) {
    if (body->getCollisionShape() != &shape) continue;
    state.mesh = nullptr;
    state.valid = false;
  }
}

const FIGNetStepStats& FIGNetDynamicsWorld::last_step_stats() const {
  return impl_->stats;
}

void FIGNetDynamicsWorld::removeRigidBody(btRigidBody* body) {
  impl_->states.erase(body);
  btDiscreteDynamicsWorld::removeRigidBody(body);
}

void FIGNetDynamicsWorld::removeCollisionObject(btCollisionObject* object) {
  impl_->states.erase(object);
  btDiscreteDynamicsWorld::removeCollisionObject(object);
}

void FIGNetDynamicsWorld::updateAabbs() {
  const double radius = impl_->graph.collision_radius;
  for (int i = 0; i < m_collisionObjects.size(); ++i) {
    btCollisionObject* object = m_collisionObjects[i];
    if (!m_forceUpdateAllAabbs && !object->isActive()) continue;
    btVector3 lower, upper;
    object->getCollisionShape()->getAabb(object->getWorldTransform(), lower, upper);
    // Boxes grown by d_c/2 each overlap when their bodies are within d_c; a moving body's box
    // also covers the distance it moved last step, so it cannot pass through what it nears.
    double grow = radius / 2;
    if (impl_->options.grow_search_by_travel) {
      const auto state = impl_->states.find(object);
      if (state != impl_->states.end()) grow += state->second.travel;
    }
    const btScalar g = static_cast<btScalar>(grow);
    const btVector3 margin(g, g, g);
    lower -= margin, upper += margin;
    if (!object->isStaticObject() && (upper - lower).length2() >= btScalar(1e12)) {
      throw ConfigError(
          fmt::format("FIGNetDynamicsWorld: a moving body's bounding box is {} m "
                      "across (did it fly away or get NaN?)",
                      (upper - lower).length()));
    }
    m_broadphasePairCache->setAabb(object->getBroadphaseHandle(), lower, upper, m_dispatcher1);
  }
}

void FIGNetDynamicsWorld::internalSingleStepSimulation(btScalar time_step) {
  Impl& impl = *impl_;
  if (!impl.options.allow_time_step_mismatch &&
      std::abs(time_step - impl.time_step) > 1e-6 * impl.time_step) {
    throw ConfigError(fmt::format(
        "FIGNetDynamicsWorld: fixed time step {} s differs from the model's {} s (1/{:.0f} s); "
        "call stepSimulation(dt, maxSubSteps, {:.9g})",
        time_step, impl.time_step, 1.0 / impl.time_step, impl.time_step));
  }
  if (m_internalPreTickCallback) (*m_internalPreTickCallback)(this, time_step);
  const auto start = Clock::now();
  impl.stats = {};
  // Forces other than gravity (applyForce, applyTorque) become a velocity change over the step;
  // impulses already changed the velocity. Either reseeds the body's history.
  for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
    btRigidBody* body = m_nonStaticRigidBodies[i];
    if (body->isStaticOrKinematicObject() || !body->isActive()) continue;
    const btVector3 gravity = body->getGravity();
    if (!impl.options.allow_gravity_mismatch &&
        (from_bt(gravity) - impl.gravity).norm() > 1e-5 * std::max(1.0, impl.gravity.norm())) {
      throw ConfigError(fmt::format(
          "FIGNetDynamicsWorld: a body falls with gravity ({}, {}, {}), the model was trained "
          "with ({}, {}, {})",
          gravity.x(), gravity.y(), gravity.z(), impl.gravity.x(), impl.gravity.y(),
          impl.gravity.z()));
    }
    const btVector3 extra = body->getTotalForce() - gravity / body->getInvMass();
    if (extra.length() > 1e-6 * gravity.length() / body->getInvMass() + 1e-12) {
      body->setLinearVelocity(body->getLinearVelocity() + extra * body->getInvMass() * time_step);
    }
    if (body->getTotalTorque().length() > 0) {
      body->setAngularVelocity(body->getAngularVelocity() + body->getInvInertiaTensorWorld() *
                                                                body->getTotalTorque() * time_step);
    }
  }
  updateAabbs();
  computeOverlappingPairs();
  impl.collect_pairs_and_islands(*this);
  impl.build_scene();
  impl.stats.prepare_seconds = seconds_since(start);

  const auto predict_start = Clock::now();
  if (!impl.simulated.empty()) {
    impl.predictor->predict_with_candidates(impl.scene, impl.candidates,
                                            impl.workspace.accelerations);
    integrate_next_poses(impl.scene, impl.next, impl.workspace);
    impl.guard_fast_bodies(*this);
  }
  impl.stats.predict_seconds = seconds_since(predict_start);

  const auto write_start = Clock::now();
  impl.write_back();
  impl.record_kinematic_poses(*this);
  impl.record_face_lines();
  impl.stats.write_back_seconds = seconds_since(write_start);
  impl.stats.simulated_bodies = static_cast<int>(impl.simulated.size());
  impl.stats.sleeping_bodies = static_cast<int>(impl.dynamic_bodies.size() - impl.simulated.size());
  impl.stats.kinematic_objects =
      static_cast<int>(impl.scene.objects.size() - impl.simulated.size());
  impl.stats.candidate_pairs = static_cast<int>(impl.candidates.size());
  impl.stats.face_edges = impl.predictor->last_face_edges();
  if (m_internalTickCallback) (*m_internalTickCallback)(this, time_step);
}

void FIGNetDynamicsWorld::debugDrawWorld() {
  btDiscreteDynamicsWorld::debugDrawWorld();
  btIDebugDraw* drawer = getDebugDrawer();
  if (!drawer) return;
  const btVector3 color(1.0f, 0.5f, 0.0f);
  for (const auto& [a, b] : impl_->face_lines) drawer->drawLine(to_bt(a), to_bt(b), color);
}

}  // namespace fignet::bullet
