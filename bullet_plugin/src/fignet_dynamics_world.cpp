#include "fignet/bullet/fignet_dynamics_world.h"

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <LinearMath/btTransformUtil.h>
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
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

// The node budget a world of this model uses when the options leave it to the model.
FIGNetWorldOptions with_model_budget(FIGNetWorldOptions options, const ModelConfig& config) {
  if (options.max_graph_vertices == FIGNetWorldOptions::kModelResolution &&
      config.mesh_vertices > 0) {
    options.max_graph_vertices = config.mesh_vertices;
  }
  return options;
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

  std::optional<GraphBuilder> contact_query;  // which bodies have collision edges

  // Per-step scratch.
  Scene scene;
  std::vector<btRigidBody*> dynamic_bodies;  // all dynamic rigid bodies of the world
  std::vector<btRigidBody*> moving;          // the awake ones, advanced this step
  std::vector<char> in_network;              // per moving body: predicted by the network
  std::vector<int> networked;     // moving bodies that are scene.objects[0 … n), in order
  std::vector<char> interacting;  // per scene object: has a collision edge
  std::unordered_map<const btCollisionObject*, int> scene_index;
  std::unordered_map<const btCollisionObject*, int> dynamic_index;  // into dynamic_bodies
  std::unordered_map<const btCollisionObject*, int> moving_index;   // into moving
  std::vector<std::unique_ptr<TriangleMesh>> pieces;  // static-mesh triangles near bodies
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;
  std::vector<ObjectPair> candidates;
  std::vector<std::pair<btCollisionObject*, btCollisionObject*>> pairs;
  std::vector<int> island;
  StepWorkspace workspace;
  std::vector<Pose> network_next;  // per scene object
  std::vector<Pose> next;          // per moving body

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
      } else if (options.sleeping && !asleep[root] && ready[root] && body->isActive()) {
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
    if (const std::optional<Floor> floor = as_floor(object);
        floor && graph.floor != FloorModel::kNone) {
      if (!scene.floor) scene.floor = floor;
      if (!near_floor(dynamic, *floor)) return;
      // A mesh floor is an object of the graph (its index is known once all objects are); an
      // implicit one is in every node's features.
      if (graph.floor == FloorModel::kMesh) candidates.push_back({partner, -1});
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

  // The awake dynamic bodies, their histories brought up to date.
  void collect_moving() {
    moving.clear();
    moving_index.clear();
    for (btRigidBody* body : dynamic_bodies) {
      if (!body->isActive()) continue;
      state_of(*body);
      moving_index[body] = static_cast<int>(moving.size());
      moving.push_back(body);
    }
  }

  // Whether a moving body has a vertex within the collision radius of the floor plane: a static
  // plane's broadphase box spans everything, so it pairs with every body.
  bool near_floor(const btCollisionObject& body, const Floor& floor) const {
    const BodyState& state = states.at(&body);
    const Pose& pose = state.poses.back();
    const Eigen::RowVector3d up = pose.orientation.toRotationMatrix().row(2);
    const double lowest = pose.position.z() + (state.mesh->vertices() * up.transpose()).minCoeff();
    return lowest - floor.height <= graph.collision_radius;
  }

  bool is_moving(const btCollisionObject* object) const {
    return is_dynamic(object) && object->isActive();
  }

  // The scene the network sees: the moving bodies marked in `in_network`, the static and
  // kinematic objects near them, and the object pairs to search for faces.
  void build_scene() {
    scene.objects.clear();
    scene.floor.reset();
    networked.clear();
    scene_index.clear();
    pieces.clear();
    meshes.clear();
    candidates.clear();
    for (size_t i = 0; i < moving.size(); ++i) {
      if (!in_network[i]) continue;
      btRigidBody* body = moving[i];
      scene_index[body] =
          add_object(*states[body].mesh, states[body].poses, std::nullopt,
                     {1.0 / body->getInvMass(), body->getFriction(), body->getRestitution()});
      networked.push_back(static_cast<int>(i));
    }
    auto in_scene = [&](const btCollisionObject* object) {
      return is_moving(object) && in_network[moving_index.at(object)];
    };
    for (const auto& [a, b] : pairs) {
      const bool a_in = in_scene(a), b_in = in_scene(b);
      if (a_in && b_in) {
        candidates.push_back(
            {std::min(scene_index[a], scene_index[b]), std::max(scene_index[a], scene_index[b])});
      } else if (a_in && !is_dynamic(b)) {
        add_obstacle(*b, scene_index[a], *a);
      } else if (b_in && !is_dynamic(a)) {
        add_obstacle(*a, scene_index[b], *b);
      }
    }
    // The floor: the model's own floor object, paired where the broadphase says, and centred
    // under its partners when one is far from the origin (the mesh spans ±floor_half_extent).
    const int floor_index = static_cast<int>(scene.objects.size());
    Vec3 partners_sum = Vec3::Zero();
    int partners = 0;
    bool far = false;
    for (ObjectPair& pair : candidates) {
      if (pair.b != -1) continue;
      pair.b = floor_index;
      const Vec3 center = scene.objects[pair.a].centers.row(graph.history).transpose();
      partners_sum += center;
      ++partners;
      far = far || center.head<2>().cwiseAbs().maxCoeff() > 0.5 * graph.floor_half_extent;
    }
    if (far) {
      scene.floor->center_x = partners_sum.x() / partners;
      scene.floor->center_y = partners_sum.y() / partners;
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

  // Which moving bodies the network predicts: all of them, or, with free flight, those with a
  // collision edge (a body without any broadphase pair has none for certain; the others are
  // searched as the graph builder will search them).
  void choose_network_bodies() {
    in_network.assign(moving.size(), options.free_flight ? 0 : 1);
    if (options.free_flight) {
      auto may_touch = [&](const btCollisionObject* body, const btCollisionObject* other) {
        if (!is_moving(body)) return false;
        if (is_moving(other)) return true;
        if (is_dynamic(other)) return false;  // asleep
        const std::optional<Floor> floor = as_floor(*other);
        return !floor || graph.floor == FloorModel::kNone || near_floor(*body, *floor);
      };
      for (const auto& [a, b] : pairs) {
        if (may_touch(a, b)) in_network[moving_index.at(a)] = 1;
        if (may_touch(b, a)) in_network[moving_index.at(b)] = 1;
      }
    }
    build_scene();
    if (!options.free_flight || networked.empty()) return;
    contact_query->find_interacting_objects(scene, candidates, interacting);
    bool all_interact = true;
    for (size_t k = 0; k < networked.size(); ++k) {
      if (interacting[k]) continue;
      in_network[networked[k]] = 0;
      all_interact = false;
    }
    if (!all_interact) build_scene();
  }

  // Free flight: x_{t+1} = 2x_t − x_{t−1} + g·dt², exact for constant acceleration (applied
  // forces are already in the history's last velocity), and the last step's rotation again (the
  // graph config guarantees a history of at least one past pose).
  Pose free_flight_pose(const btRigidBody& body) const {
    const std::vector<Pose>& poses = states.at(&body).poses;
    const Pose& current = poses.back();
    const Pose& previous = poses[poses.size() - 2];
    Pose next;
    next.position = 2.0 * current.position - previous.position +
                    time_step * time_step * from_bt(body.getGravity());
    next.orientation =
        (current.orientation * previous.orientation.conjugate() * current.orientation).normalized();
    return next;
  }

  // Next poses of every moving body: the network's for the bodies in contact, free flight for
  // the others.
  void advance() {
    next.resize(moving.size());
    if (!networked.empty()) {
      predictor->predict_with_candidates(scene, candidates, workspace.accelerations);
      integrate_next_poses(scene, network_next, workspace);
      for (size_t k = 0; k < networked.size(); ++k) next[networked[k]] = network_next[k];
    }
    for (size_t i = 0; i < moving.size(); ++i) {
      if (!in_network[i]) next[i] = free_flight_pose(*moving[i]);
    }
  }

  // The tunnelling guard. A step longer than the collision radius can carry a body past a surface
  // that was never within the graph's reach; such a step is swept with the body's convex shape
  // (or, for compounds, a sphere inside it) and, if it would cross a surface it moves against,
  // the body stops where it touches, as Bullet's CCD stops a body.
  void guard_fast_bodies(btCollisionWorld& world) {
    if (!options.sweep_guard) return;
    for (size_t i = 0; i < moving.size(); ++i) {
      btRigidBody& body = *moving[i];
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

  // The deepest penetration of one body into static geometry, from Bullet's narrow phase.
  struct StaticPenetration : btCollisionWorld::ContactResultCallback {
    explicit StaticPenetration(const btCollisionObject* self) : self_(self) {
      m_collisionFilterGroup = self->getBroadphaseHandle()->m_collisionFilterGroup;
      m_collisionFilterMask = self->getBroadphaseHandle()->m_collisionFilterMask;
    }
    bool needsCollision(btBroadphaseProxy* proxy) const override {
      const auto* other = static_cast<const btCollisionObject*>(proxy->m_clientObject);
      return ContactResultCallback::needsCollision(proxy) && other != self_ &&
             other->isStaticObject() && other->hasContactResponse();
    }
    btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper* first, int,
                             int, const btCollisionObjectWrapper*, int, int) override {
      const double penetration = -point.getDistance();
      if (penetration <= depth) return 0;
      // The normal points from the second object to the first: out of the static one when the
      // body is first.
      const Vec3 normal = from_bt(point.m_normalWorldOnB);
      out = first->getCollisionObject() == self_ ? normal : Vec3(-normal);
      depth = penetration;
      return 0;
    }
    const btCollisionObject* self_;
    double depth = 0.0;
    Vec3 out = Vec3::Zero();
  };

  // The penetration guard (after write_back): a body deeper than the tolerance in static
  // geometry moves out along the contact normal, history included, so the network does not see
  // the correction as velocity; the inward part of its velocity goes. A few passes let a body
  // wedged against two surfaces leave both.
  void recover_static_penetrations(btCollisionWorld& world) {
    if (!options.penetration_guard) return;
    for (btRigidBody* body : moving) {
      BodyState& state = states[body];
      bool moved = false;
      for (int pass = 0; pass < 4; ++pass) {
        StaticPenetration contact(body);
        world.contactTest(body, contact);
        if (contact.depth <= options.penetration_tolerance) break;
        const Vec3 push = contact.depth * contact.out;
        for (Pose& pose : state.poses) pose.position += push;
        // v' = v − min(0, v·n)·n, v the history's last velocity (what write_back gave Bullet);
        // the previous poses shift to match it.
        const size_t h = state.poses.size() - 1;
        const Vec3 velocity = (state.poses[h].position - state.poses[h - 1].position) / time_step;
        const double inward = std::min(0.0, velocity.dot(contact.out));
        for (size_t k = 0; k < h; ++k) state.poses[k].position += inward * time_step * contact.out;
        body->setLinearVelocity(to_bt(Vec3(velocity - inward * contact.out)));
        body->proceedToTransform(to_bt(state.poses.back()));
        moved = true;
      }
      if (!moved) continue;
      ++stats.recovered_bodies;
      state.written = body->getWorldTransform();
      state.written_linear = body->getLinearVelocity();
    }
  }

  // New poses, velocities and interpolation state of the moving bodies.
  void write_back() {
    for (size_t i = 0; i < moving.size(); ++i) {
      btRigidBody& body = *moving[i];
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
    if (networked.empty()) return;
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
                          with_model_budget(options, model->config())) {}

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
  impl_->contact_query.emplace(graph);
  if (options.penetration_tolerance < 0 || !std::isfinite(options.penetration_tolerance)) {
    throw ConfigError(fmt::format(
        "FIGNetDynamicsWorld: penetration_tolerance is {} m; it must be finite and >= 0",
        options.penetration_tolerance));
  }
  const int budget = options.max_graph_vertices == FIGNetWorldOptions::kModelResolution
                         ? FIGNetWorldOptions::kDefaultGraphVertices
                         : options.max_graph_vertices;
  if (budget < 0 || (budget > 0 && budget < 4) ||
      !(options.simplify_tolerance > 0.0 && options.simplify_tolerance <= 1.0)) {
    throw ConfigError(fmt::format(
        "FIGNetDynamicsWorld: max_graph_vertices {} (0 for none, or >= 4) and simplify_tolerance "
        "{} (in (0, 1])",
        options.max_graph_vertices, options.simplify_tolerance));
  }
  if (budget > 0) impl_->shapes = ShapeMeshCache({budget, options.simplify_tolerance});
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

Pose FIGNetDynamicsWorld::precise_pose(const btCollisionObject& object) const {
  const auto state = impl_->states.find(&object);
  if (state != impl_->states.end() && state->second.valid && !state->second.poses.empty() &&
      object.getWorldTransform() == state->second.written) {
    return state->second.poses.back();
  }
  return from_bt(object.getWorldTransform());
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
  impl.collect_moving();
  impl.choose_network_bodies();
  impl.stats.prepare_seconds = seconds_since(start);

  const auto predict_start = Clock::now();
  impl.advance();
  impl.guard_fast_bodies(*this);
  impl.stats.predict_seconds = seconds_since(predict_start);

  const auto write_start = Clock::now();
  impl.write_back();
  impl.recover_static_penetrations(*this);
  impl.record_kinematic_poses(*this);
  impl.record_face_lines();
  impl.stats.write_back_seconds = seconds_since(write_start);
  const int networked = static_cast<int>(impl.networked.size());
  impl.stats.simulated_bodies = networked;
  impl.stats.free_flight_bodies = static_cast<int>(impl.moving.size()) - networked;
  impl.stats.sleeping_bodies = static_cast<int>(impl.dynamic_bodies.size() - impl.moving.size());
  impl.stats.kinematic_objects = static_cast<int>(impl.scene.objects.size()) - networked;
  impl.stats.candidate_pairs = static_cast<int>(impl.candidates.size());
  impl.stats.face_edges = networked > 0 ? impl.predictor->last_face_edges() : 0;
  impl.stats.mesh_nodes = 0;
  if (networked > 0) {
    for (const SceneObject& object : impl.scene.objects) {
      impl.stats.mesh_nodes += object.mesh->num_vertices();
    }
  }
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
