#include "fignet/bullet/fignet_dynamics_world.h"

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <LinearMath/btTransformUtil.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "fignet/bullet/conversions.h"
#include "fignet/bullet/shape_mesh.h"
#include "fignet/error.h"
#include "fignet/geometry/triangle_distance.h"
#include "fignet/graph/contacts.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/rollout/free_flight.h"
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

// Whether two graph configs find the same collision pairs in a scene: then the world's search
// can stand for the predictor's.
bool same_contact_search(const GraphConfig& a, const GraphConfig& b) {
  return a.collision_radius == b.collision_radius && a.collisions == b.collisions &&
         a.floor == b.floor && a.floor_half_extent == b.floor_half_extent &&
         a.floor_segments == b.floor_segments;
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

// Poses h, h−1, …, 0 steps back from `current`, moving with constant velocities (oldest first),
// the centre of mass on the parabola of `acceleration` (zero: a straight line) through the
// current position with the current velocity.
std::vector<Pose> seed_history(const Pose& current, const Vec3& linear, const Vec3& angular,
                               int history, double dt, const Vec3& acceleration = Vec3::Zero()) {
  std::vector<Pose> poses(history + 1);
  for (int k = 0; k <= history; ++k) {
    const double tau = (k - history) * dt;  // <= 0
    poses[k].position = current.position + tau * linear + 0.5 * tau * tau * acceleration;
    const Vec3 angle = tau * angular;
    poses[k].orientation =
        angle.norm() > 0
            ? (Eigen::AngleAxisd(angle.norm(), angle.normalized()) * current.orientation)
                  .normalized()
            : current.orientation;
  }
  return poses;
}

// How far Bullet's collision surface lies outside the mesh the network sees: the margin of the
// shapes that add it around their points (hulls, triangle meshes); boxes, spheres, cylinders and
// cones keep theirs inside their dimensions.
double margin_outside(const btCollisionShape& shape) {
  switch (shape.getShapeType()) {
    case CONVEX_HULL_SHAPE_PROXYTYPE:
    case CONVEX_POINT_CLOUD_SHAPE_PROXYTYPE:
    case CONVEX_TRIANGLEMESH_SHAPE_PROXYTYPE:
    case TRIANGLE_MESH_SHAPE_PROXYTYPE:
    case SCALED_TRIANGLE_MESH_SHAPE_PROXYTYPE:
    case GIMPACT_SHAPE_PROXYTYPE:
      return shape.getMargin();
    case COMPOUND_SHAPE_PROXYTYPE: {
      const auto& compound = static_cast<const btCompoundShape&>(shape);
      double widest = 0.0;
      for (int i = 0; i < compound.getNumChildShapes(); ++i)
        widest = std::max(widest, margin_outside(*compound.getChildShape(i)));
      return widest;
    }
    default:
      return 0.0;
  }
}

// Whether `point` lies within `margin` of the convex hull of `support` (2D, Andrew's monotone
// chain). Reorders `support`.
bool within_hull(std::vector<Eigen::Vector2d>& support, const Eigen::Vector2d& point,
                 double margin) {
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::sort(support.begin(), support.end(), [](const auto& a, const auto& b) {
    return std::tie(a.x(), a.y()) < std::tie(b.x(), b.y());
  });
  std::vector<Eigen::Vector2d> hull(2 * support.size());
  size_t k = 0;
  for (size_t i = 0; i < support.size(); ++i) {  // lower hull
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], support[i]) <= 0) --k;
    hull[k++] = support[i];
  }
  for (size_t i = support.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && cross(hull[k - 2], hull[k - 1], support[i]) <= 0) --k;
    hull[k++] = support[i];
  }
  hull.resize(k > 1 ? k - 1 : k);  // counter-clockwise, the first point not repeated
  auto distance_to_segment = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d ab = b - a;
    const double t =
        ab.squaredNorm() > 0 ? std::clamp((point - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    return (a + t * ab - point).norm();
  };
  if (hull.empty()) return false;
  if (hull.size() == 1) return (hull[0] - point).norm() <= margin;
  if (hull.size() == 2) return distance_to_segment(hull[0], hull[1]) <= margin;
  bool inside = true;
  double nearest = INFINITY;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    inside = inside && cross(a, b, point) >= 0;
    nearest = std::min(nearest, distance_to_segment(a, b));
  }
  return inside || nearest <= margin;
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
  // The model's config, for its data's materials (unknown ranges with a stand-in predictor).
  ModelConfig model_config;
  std::vector<std::pair<Vec3, Vec3>> face_lines;  // last step's face–face edges, for drawing

  std::optional<GraphBuilder> contact_query;  // which bodies have collision edges

  // Per-step scratch.
  Scene scene;
  std::vector<btRigidBody*> dynamic_bodies;  // all dynamic rigid bodies of the world
  std::vector<btRigidBody*> moving;          // the awake ones, advanced this step
  std::vector<char> in_network;              // per moving body: predicted by the network
  std::vector<int> networked;     // moving bodies that are scene.objects[0 … n), in order
  std::vector<char> interacting;  // per scene object: has a collision edge
  SceneContacts contacts;         // and the collision pairs of that search
  bool scene_searched = false;    // the search was of the scene as it stands: the network reuses it
  bool share_search = true;       // the predictor searches as contact_query does
  std::vector<const btCollisionObject*> scene_owners;  // per scene object: whose it is
  // The floor plane, and the groups of its partners that each get a floor mesh of their own.
  struct FloorGroup {
    Eigen::Vector2d seed, sum = Eigen::Vector2d::Zero();
    int partners = 0;
    bool far = false;  // a partner is far from the origin, where training had the floor
    int index = -1;    // the floor's scene object
  };
  const btCollisionObject* floor_owner = nullptr;
  TriangleMesh floor_patch;
  std::vector<FloorGroup> floor_groups;
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
  // The rest guard's scratch: bodies pushed by a force other than gravity this step, and per
  // moving body whether it may rest, whether it is held, and its contacts.
  struct RestContact {
    const btCollisionObject* other;  // nullptr: the floor
    Vec3 point, normal;              // a point of the contact; out of the other into the body
    double friction;                 // Bullet's combined friction of the two
  };
  static constexpr double kFromBelow = 0.1;  // a contact normal this far up pushes against gravity
  std::unordered_set<const btCollisionObject*> pushed;
  std::vector<char> may_rest, held;
  std::vector<std::vector<RestContact>> rest_contacts;
  std::vector<Eigen::Vector2d> support;
  ContactFinder rest_finder;
  std::vector<PosedMesh> posed;
  std::vector<ObjectPair> touching_candidates;
  std::vector<FacePair> touching_faces;
  std::vector<double> object_margins;  // per scene object: margin_outside of its shape

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
  // or the user moved it or changed its velocity since the last step. A body reseeded in free
  // flight (nothing within the collision radius) falls along its gravity's parabola in the
  // history, as it did in the training data; one that may be supported keeps a straight line
  // (a parabola would show a resting body as one that was falling onto what holds it).
  BodyState& state_of(btRigidBody& body) {
    BodyState& state = with_mesh(body);
    const bool unchanged = state.valid && body.getWorldTransform() == state.written &&
                           body.getLinearVelocity() == state.written_linear &&
                           body.getAngularVelocity() == state.written_angular;
    if (!unchanged) {
      const Pose current = from_bt(body.getWorldTransform());
      const Vec3 linear = from_bt(body.getLinearVelocity());
      const Vec3 angular = from_bt(body.getAngularVelocity());
      // Straight first: in_free_flight reads the body's current pose from its history.
      state.poses = seed_history(current, linear, angular, graph.history, time_step);
      state.valid = true;
      if (options.seed_falling && in_free_flight(body)) {
        state.poses = seed_history(current, linear, angular, graph.history, time_step,
                                   from_bt(body.getGravity()));
      }
    }
    return state;
  }

  // A dynamic body's state with its mesh and bounding radius, its history not yet set.
  BodyState& with_mesh(const btCollisionObject& body) {
    BodyState& state = states[&body];
    if (!state.mesh) {
      state.mesh = shapes.mesh_of(*body.getCollisionShape());
      state.radius = state.mesh->vertices().rowwise().norm().maxCoeff();
    }
    return state;
  }

  // Whether a body touches nothing within the collision radius, by its broadphase partners: a
  // floor plane more than the radius below its mesh, a dynamic body whose bounding sphere is
  // more than the radius from its own (broadphase boxes of large tilted bodies overlap well
  // before the bodies meet). Other static or kinematic geometry may hold it. Needs this step's
  // pairs and the body's current pose in its history.
  bool in_free_flight(const btCollisionObject& body) {
    const double radius = with_mesh(body).radius;
    const btVector3 centre = body.getWorldTransform().getOrigin();
    for (const auto& [a, b] : pairs) {
      if (a != &body && b != &body) continue;
      const btCollisionObject& other = a == &body ? *b : *a;
      if (const std::optional<Floor> floor = as_floor(other)) {
        if (near_floor(body, *floor)) return false;
      } else if (is_dynamic(&other)) {
        const double reach = radius + with_mesh(other).radius + graph.collision_radius;
        if ((other.getWorldTransform().getOrigin() - centre).length() <= reach) return false;
      } else {
        return false;
      }
    }
    return true;
  }

  int add_object(const btCollisionObject& owner, const TriangleMesh& mesh,
                 std::span<const Pose> poses, const std::optional<Pose>& next_pose,
                 const StaticProperties& properties) {
    scene_owners.push_back(&owner);
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
      if (!scene.floor) {
        scene.floor = floor;
        floor_owner = &object;
      }
      if (!near_floor(dynamic, *floor)) return;
      // A mesh floor is an object of the graph (its index is known once all objects are); an
      // implicit one is in every node's features.
      if (graph.floor == FloorModel::kMesh) candidates.push_back({partner, -1});
      return;
    }
    const StaticProperties properties{0.0, object.getFriction(), object.getRestitution()};
    if (is_dynamic(&object)) {
      // A body held by the rest guard: it does not move, and keeps the mesh the network knows.
      auto found = scene_index.find(&object);
      if (found == scene_index.end()) {
        const BodyState& state = states.at(&object);
        found = scene_index
                    .emplace(&object, add_object(object, *state.mesh, state.poses,
                                                 state.poses.back(), properties))
                    .first;
      }
      candidates.push_back({partner, found->second});
      return;
    }
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
      candidates.push_back({partner, add_object(object, *pieces.back(), poses, pose, properties)});
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
          scene_index.emplace(&object, add_object(object, *meshes.back(), poses, next, properties))
              .first;
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

  // The floor: the model's own floor mesh (±floor_half_extent), paired where the broadphase
  // says. Training had it centred on the origin under every body; here it is centred under its
  // partners when one is far from the origin, and partners farther apart than a quarter of the
  // mesh's reach are grouped, each group under a floor patch of its own (a kinematic object of
  // the same mesh and properties), so that no body is near a floor mesh's edge.
  void place_floor() {
    const double join = 0.25 * graph.floor_half_extent;
    floor_groups.clear();
    for (ObjectPair& pair : candidates) {
      if (pair.b != -1) continue;
      const Vec3 center = scene.objects[pair.a].centers.row(graph.history).transpose();
      size_t g = 0;
      while (g < floor_groups.size() && (floor_groups[g].seed - center.head<2>()).norm() > join) {
        ++g;
      }
      if (g == floor_groups.size()) floor_groups.push_back({center.head<2>()});
      FloorGroup& group = floor_groups[g];
      group.sum += center.head<2>();
      ++group.partners;
      group.far =
          group.far || center.head<2>().cwiseAbs().maxCoeff() > 0.5 * graph.floor_half_extent;
      pair.b = -2 - static_cast<int>(g);
    }
    // Where a group's floor is centred: the origin as in training, or under the group.
    auto center_of = [&](const FloorGroup& group) {
      return group.far ? Eigen::Vector2d(group.sum / group.partners) : Eigen::Vector2d::Zero();
    };
    for (size_t g = 1; g < floor_groups.size(); ++g) {
      const Eigen::Vector2d center = center_of(floor_groups[g]);
      Pose pose;
      pose.position = Vec3(center.x(), center.y(), scene.floor->height);
      const std::vector<Pose> poses(graph.history + 1, pose);
      floor_groups[g].index =
          add_object(*floor_owner, floor_patch, poses, pose, scene.floor->properties);
    }
    // The scene's own floor (the first group's) comes after every object.
    if (!floor_groups.empty()) {
      const Eigen::Vector2d center = center_of(floor_groups[0]);
      scene.floor->center_x = center.x();
      scene.floor->center_y = center.y();
      floor_groups[0].index = static_cast<int>(scene.objects.size());
    }
    for (ObjectPair& pair : candidates) {
      if (pair.b <= -2) pair.b = floor_groups[static_cast<size_t>(-2 - pair.b)].index;
    }
  }

  // The scene the network sees: the moving bodies marked in `in_network`, the static and
  // kinematic objects near them, and the object pairs to search for faces.
  void build_scene() {
    scene.objects.clear();
    scene_owners.clear();
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
          add_object(*body, *states[body].mesh, states[body].poses, std::nullopt,
                     {1.0 / body->getInvMass(), body->getFriction(), body->getRestitution()});
      networked.push_back(static_cast<int>(i));
    }
    auto in_scene = [&](const btCollisionObject* object) {
      return is_moving(object) && in_network[moving_index.at(object)];
    };
    auto is_held = [&](const btCollisionObject* object) {
      return is_moving(object) && held[moving_index.at(object)];
    };
    for (const auto& [a, b] : pairs) {
      const bool a_in = in_scene(a), b_in = in_scene(b);
      if (a_in && b_in) {
        candidates.push_back(
            {std::min(scene_index[a], scene_index[b]), std::max(scene_index[a], scene_index[b])});
      } else if (a_in && (!is_dynamic(b) || is_held(b))) {
        add_obstacle(*b, scene_index[a], *a);
      } else if (b_in && (!is_dynamic(a) || is_held(a))) {
        add_obstacle(*a, scene_index[b], *b);
      }
    }
    place_floor();
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
  void choose_network_bodies(btCollisionWorld& world) {
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
    held.assign(moving.size(), 0);
    build_scene();
    // Bodies that stand at rest leave the network first (the cheaper test); to the bodies near
    // them they are obstacles that do not move.
    if (hold_resting_bodies(world)) build_scene();
    scene_searched = false;
    if (options.free_flight && !networked.empty()) {
      contact_query->find_interacting_objects(scene, candidates, interacting, &contacts);
      bool all_interact = true;
      for (size_t k = 0; k < networked.size(); ++k) {
        if (interacting[k]) continue;
        in_network[networked[k]] = 0;
        all_interact = false;
      }
      // A scene rebuilt without the bodies in free flight numbers its objects anew and is
      // searched again; one that stands is not.
      if (all_interact) {
        scene_searched = share_search;
      } else {
        build_scene();
      }
    }
  }

  // Free flight (rollout/free_flight.h) under the body's own gravity (applied forces are already
  // in the history's last velocity; the graph config guarantees a history of at least one past
  // pose).
  Pose free_flight_pose(const btRigidBody& body) const {
    const std::vector<Pose>& poses = states.at(&body).poses;
    return fignet::free_flight_pose(poses[poses.size() - 2], poses.back(),
                                    time_step * time_step * from_bt(body.getGravity()));
  }

  // Next poses of every moving body: the network's for the bodies in contact, free flight for
  // the others.
  void advance() {
    next.resize(moving.size());
    if (!networked.empty()) {
      if (scene_searched) {
        predictor->predict_with_search(scene, candidates, interacting, contacts,
                                       workspace.accelerations);
      } else {
        predictor->predict_with_candidates(scene, candidates, workspace.accelerations);
      }
      integrate_next_poses(scene, network_next, workspace);
      for (size_t k = 0; k < networked.size(); ++k) next[networked[k]] = network_next[k];
    }
    for (size_t i = 0; i < moving.size(); ++i) {
      if (held[i]) {
        next[i] = states.at(moving[i]).poses.back();
      } else if (!in_network[i]) {
        next[i] = free_flight_pose(*moving[i]);
      }
    }
  }

  // The tunnelling guard, by Bullet's CCD rule: a step longer than the collision radius is swept
  // with a sphere deep inside the body (Bullet's swept sphere), and only a step that would carry
  // that core into a surface is the guard's. Contacts the graph reaches, and the shallow
  // penetrations of fast impacts, are the network's (and the penetration guard's): the data
  // holds them, and stopping a body at every surface it nears at training speeds took its
  // velocity at every impact. A guarded body stops where its own shape first touches the
  // surface (convex shapes; the core's hit for others) and keeps its velocity along it; the part
  // into it goes, history included, as the penetration guard's does.
  void guard_fast_bodies(btCollisionWorld& world) {
    if (!options.sweep_guard) return;
    for (size_t i = 0; i < moving.size(); ++i) {
      btRigidBody& body = *moving[i];
      BodyState& state = states[&body];
      const Pose current = state.poses.back();
      Pose& next_pose = next[i];
      const Vec3 motion = next_pose.position - current.position;
      if (motion.norm() <= graph.collision_radius) continue;
      Pose to = current;
      to.position = next_pose.position;
      // The core: half the body's smallest half-width, about its centre of mass.
      const btCollisionShape* shape = body.getCollisionShape();
      btVector3 low, high;
      shape->getAabb(btTransform::getIdentity(), low, high);
      const btVector3 size = high - low;
      const btSphereShape core(0.25f * size[size.minAxis()]);
      SweepCallback core_hit(&body, to_bt(current.position), to_bt(to.position));
      world.convexSweepTest(&core, to_bt(current), to_bt(to), core_hit);
      if (!core_hit.hasHit()) continue;
      double fraction = core_hit.m_closestHitFraction;
      Vec3 normal = from_bt(core_hit.m_hitNormalWorld);
      if (shape->isConvex()) {
        SweepCallback touch(&body, to_bt(current.position), to_bt(to.position));
        world.convexSweepTest(static_cast<const btConvexShape*>(shape), to_bt(current), to_bt(to),
                              touch);
        if (touch.hasHit() && touch.m_closestHitFraction <= fraction) {
          fraction = touch.m_closestHitFraction;
          normal = from_bt(touch.m_hitNormalWorld);
        }
      }
      next_pose.position = current.position + fraction * motion;
      next_pose.orientation = current.orientation.slerp(fraction, next_pose.orientation);
      // v' = v − min(0, v·n)·n with v the predicted velocity; write_back reads the velocity off
      // the history, so the history moves to end v'·dt behind the stop.
      if (normal.norm() > 0) normal.normalize();
      const Vec3 velocity = motion / time_step;
      const Vec3 kept = velocity - std::min(0.0, velocity.dot(normal)) * normal;
      const Vec3 shift = next_pose.position - kept * time_step - current.position;
      for (Pose& pose : state.poses) pose.position += shift;
      ++stats.guarded_bodies;
    }
  }

  // Kinetic energy of a body over one step from `from` to `to`, linear and rotational, by the
  // finite-difference velocities the network reads.
  double kinetic_energy(const btRigidBody& body, const Pose& from, const Pose& to) const {
    const Vec3 linear = (to.position - from.position) / time_step;
    const Eigen::AngleAxisd turn(to.orientation * from.orientation.conjugate());
    const Vec3 angular = turn.axis() * (turn.angle() / time_step);
    // I_world = R·I_local·Rᵀ: the rotational energy ½·ωᵀ·I·ω in the body's frame.
    const Vec3 local = to.orientation.conjugate() * angular;
    const btVector3 inverse = body.getInvInertiaDiagLocal();
    double rotational = 0.0;
    for (int k = 0; k < 3; ++k) {
      if (inverse[k] > 0) rotational += local[k] * local[k] / inverse[k];
    }
    return 0.5 * linear.squaredNorm() / body.getInvMass() + 0.5 * rotational;
  }

  // The energy guard (options.energy_guard). Per island of the bodies the network moved: the
  // kinetic energy before (last step's velocities) and after (the predicted step) and the
  // potential energy the step adds; an island that gains more than its allowance has every
  // member's step scaled by one factor s, the largest for which K·s² + W·s ≤ B (K the predicted
  // kinetic energy, W the potential energy the whole step adds, B the kinetic energy before plus
  // the allowance).
  void guard_energy() {
    if (!options.energy_guard || networked.empty()) return;
    struct Island {
      double kinetic_before = 0, kinetic_after = 0, added_potential = 0, lift = 0;
      bool driven = false;
      std::vector<size_t> members;
    };
    std::unordered_map<int, Island> islands;
    for (const int i : networked) {
      btRigidBody& body = *moving[static_cast<size_t>(i)];
      if (body.getInvMass() == 0) continue;
      Island& island = islands[find(dynamic_index.at(&body))];
      const std::vector<Pose>& poses = states.at(&body).poses;
      const Pose& current = poses.back();
      const Pose& next_pose = next[static_cast<size_t>(i)];
      const double mass = 1.0 / body.getInvMass();
      const Vec3 gravity = from_bt(body.getGravity());
      island.kinetic_before += kinetic_energy(body, poses[poses.size() - 2], current);
      island.kinetic_after += kinetic_energy(body, current, next_pose);
      island.added_potential -= mass * gravity.dot(next_pose.position - current.position);
      island.lift += mass * gravity.norm() * 1e-3;
      island.driven = island.driven || pushed.count(&body) > 0;
      island.members.push_back(static_cast<size_t>(i));
    }
    // Islands a kinematic body touches are driven by it.
    for (const auto& [a, b] : pairs) {
      for (const auto& [kinematic, other] : {std::pair{a, b}, std::pair{b, a}}) {
        if (!kinematic->isKinematicObject() || !is_dynamic(other)) continue;
        const auto found = islands.find(find(dynamic_index.at(other)));
        if (found != islands.end()) found->second.driven = true;
      }
    }
    for (auto& [root, island] : islands) {
      if (island.driven || island.kinetic_after <= 0) continue;
      const double budget = (1 + options.energy_tolerance) * island.kinetic_before + island.lift;
      const double K = island.kinetic_after, W = island.added_potential;
      if (K + W <= budget) continue;
      // K > 0 and budget ≥ 0: the root is real and at least 0.
      const double s = std::min(1.0, (-W + std::sqrt(W * W + 4 * K * budget)) / (2 * K));
      for (const size_t i : island.members) {
        const Pose& current = states.at(moving[i]).poses.back();
        next[i].position = current.position + s * (next[i].position - current.position);
        next[i].orientation = current.orientation.slerp(s, next[i].orientation);
        ++stats.energy_bodies;
      }
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
  // Bullet's contacts of one body, through its own collision filter, with the other objects
  // that respond to contact (static ones only, if asked).
  struct BodyContacts : btCollisionWorld::ContactResultCallback {
    BodyContacts(const btCollisionObject* self, bool static_only)
        : self_(self), static_only_(static_only) {
      m_collisionFilterGroup = self->getBroadphaseHandle()->m_collisionFilterGroup;
      m_collisionFilterMask = self->getBroadphaseHandle()->m_collisionFilterMask;
    }
    bool needsCollision(btBroadphaseProxy* proxy) const override {
      const auto* other = static_cast<const btCollisionObject*>(proxy->m_clientObject);
      return ContactResultCallback::needsCollision(proxy) && other != self_ &&
             (!static_only_ || other->isStaticObject()) && other->hasContactResponse();
    }
    const btCollisionObject* self_;
    bool static_only_;
  };

  // The deepest penetration of one body into static geometry.
  struct StaticPenetration : BodyContacts {
    explicit StaticPenetration(const btCollisionObject* self) : BodyContacts(self, true) {}
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
    double depth = 0.0;
    Vec3 out = Vec3::Zero();
  };

  // The penetration guard (after write_back): a body deeper than the tolerance in static
  // geometry moves out along the contact normal to the tolerance, history included, so the
  // network does not see the correction as velocity; the inward part of its velocity goes. Out
  // to the tolerance, not to zero depth: a model that sinks a resting body slowly has it held
  // where it reaches the tolerance, a few hundredths of a millimetre a frame, rather than popped
  // up by the whole tolerance each time it crosses it. A few passes let a body wedged against two
  // surfaces leave both.
  static constexpr double kDepthSlack = 1e-5;  // metres; Bullet's depths are single precision
  void recover_static_penetrations(btCollisionWorld& world) {
    if (!options.penetration_guard) return;
    for (btRigidBody* body : moving) {
      BodyState& state = states[body];
      bool moved = false;
      for (int pass = 0; pass < 4; ++pass) {
        StaticPenetration contact(body);
        world.contactTest(body, contact);
        // The slack keeps a body the last pass left at the tolerance from counting again.
        if (contact.depth <= options.penetration_tolerance + kDepthSlack) break;
        const Vec3 push = (contact.depth - options.penetration_tolerance) * contact.out;
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

  // The contacts of the networked bodies, from two sources that fail in different places:
  //  - the meshes the network sees: the vertices of one object within reach of a face of the
  //    other, both ways, with the other face's outward normal (against the floor, the body's
  //    vertices within reach of it). Reach is rest_contact_distance plus the collision margins
  //    Bullet adds around hulls and triangle meshes, which keep resting meshes that far apart.
  //    It gives a flat face all its corners, where Bullet reports one point per pair of convex
  //    hulls and none for boxes a rounding error apart;
  //  - Bullet's narrow phase on the collision shapes (contactTest): a sphere's one point under
  //    its centre, which a faceted sphere mesh has no vertex at.
  void find_rest_contacts(btCollisionWorld& world) {
    const size_t n = networked.size();
    const double reach = options.rest_contact_distance;
    for (size_t k = 0; k < n; ++k) {
      std::vector<RestContact>& contacts = rest_contacts[networked[k]];
      contacts.clear();
      ContactsOf bullet_contacts(scene_owners[k], reach, contacts);
      world.contactTest(const_cast<btCollisionObject*>(scene_owners[k]), bullet_contacts);
    }
    posed.clear();
    object_margins.clear();
    double widest = 0.0;
    for (size_t k = 0; k < scene.objects.size(); ++k) {
      const SceneObject& object = scene.objects[k];
      posed.push_back({object.mesh, object.positions_at(graph.history).data(), object.kinematic});
      object_margins.push_back(margin_outside(*scene_owners[k]->getCollisionShape()));
      widest = std::max(widest, object_margins.back());
    }
    if (scene.floor) {
      for (size_t k = 0; k < n; ++k) {
        const auto vertices = scene.objects[k].positions_at(graph.history);
        const double friction =
            btManifoldResult::calculateCombinedFriction(scene_owners[k], floor_owner);
        for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
          if (vertices(v, 2) - scene.floor->height > reach + object_margins[k]) continue;
          rest_contacts[networked[k]].push_back(
              {nullptr, vertices.row(v).transpose(), Vec3::UnitZ(), friction});
        }
      }
    }
    touching_candidates.clear();
    for (const ObjectPair& pair : candidates) {
      // The floor and its patches: the plane test above has them.
      if (pair.b >= int(scene.objects.size()) || scene_owners[pair.b] == floor_owner) continue;
      touching_candidates.push_back(pair);
    }
    rest_finder.update(posed, false);
    rest_finder.find_face_pairs(touching_candidates, reach + 2 * widest, touching_faces);
    auto triangle = [&](int object, int face) {
      const auto vertices = scene.objects[object].positions_at(graph.history);
      Triangle t;
      for (int c = 0; c < 3; ++c)
        t.v[c] = vertices.row(scene.objects[object].mesh->faces()(face, c)).transpose();
      return t;
    };
    // Vertices of `from`'s face near `onto`'s face: contacts of the networked one of the two.
    auto add_vertices = [&](int from, int face_from, int onto, int face_onto) {
      const Triangle a = triangle(from, face_from), b = triangle(onto, face_onto);
      Vec3 normal = (b.v[1] - b.v[0]).cross(b.v[2] - b.v[0]);
      if (normal.norm() == 0) return;
      normal.normalize();  // out of `onto`
      const btCollisionObject* from_owner = scene_owners[from];
      const btCollisionObject* onto_owner = scene_owners[onto];
      const double friction = btManifoldResult::calculateCombinedFriction(from_owner, onto_owner);
      const double pair_reach = reach + object_margins[from] + object_margins[onto];
      for (const Vec3& vertex : a.v) {
        if ((closest_point_on_triangle(vertex, b) - vertex).norm() > pair_reach) continue;
        if (from < int(n))
          rest_contacts[networked[from]].push_back({onto_owner, vertex, normal, friction});
        if (onto < int(n))
          rest_contacts[networked[onto]].push_back({from_owner, vertex, -normal, friction});
      }
    };
    for (const FacePair& pair : touching_faces) {
      add_vertices(pair.object_a, pair.face_a, pair.object_b, pair.face_b);
      add_vertices(pair.object_b, pair.face_b, pair.object_a, pair.face_a);
    }
  }

  // Every contact of one body on Bullet's collision shapes within a distance, seen from the body.
  struct ContactsOf : BodyContacts {
    ContactsOf(const btCollisionObject* self, double distance, std::vector<RestContact>& out)
        : BodyContacts(self, false), distance_(distance), out_(out) {
      m_closestDistanceThreshold = btScalar(distance);  // touching, not only penetrating
    }
    btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper* first, int,
                             int, const btCollisionObjectWrapper* second, int, int) override {
      if (point.getDistance() > distance_) return 0;
      // m_normalWorldOnB points from the second object to the first.
      const bool body_first = first->getCollisionObject() == self_;
      const btCollisionObject* other =
          body_first ? second->getCollisionObject() : first->getCollisionObject();
      const Vec3 normal = from_bt(point.m_normalWorldOnB);
      out_.push_back(
          {as_floor(*other) ? nullptr : other,
           from_bt(body_first ? point.getPositionWorldOnA() : point.getPositionWorldOnB()),
           body_first ? normal : Vec3(-normal),
           double(btManifoldResult::calculateCombinedFriction(self_, other))});
      return 0;
    }
    double distance_;
    std::vector<RestContact>& out_;
  };

  // Whether moving body i is slower than the friction of what lies below it stops in one step:
  // |v| and |ω|·radius <= μ·|g|·dt, μ the least combined friction of its contacts from below.
  bool slow_enough(size_t i) const {
    const BodyState& state = states.at(moving[i]);
    const Vec3 up = -gravity.normalized();
    double mu = INFINITY;
    for (const RestContact& contact : rest_contacts[i]) {
      if (contact.normal.dot(up) > kFromBelow) mu = std::min(mu, contact.friction);
    }
    if (!std::isfinite(mu)) return false;  // nothing below it
    const Pose& pose = state.poses.back();
    const Pose& previous = state.poses[state.poses.size() - 2];
    const double speed = (pose.position - previous.position).norm() / time_step;
    const double turn =
        Eigen::AngleAxisd(pose.orientation * previous.orientation.conjugate()).angle();
    const double limit = mu * gravity.norm() * time_step;
    return speed <= limit && std::abs(turn) / time_step * state.radius <= limit;
  }

  // Whether slow body i stands (see FIGNetWorldOptions::rest_guard), given the bodies held so
  // far. nullopt: it stands on a body whose own rest is not decided yet.
  std::optional<bool> stands(size_t i) {
    const BodyState& state = states.at(moving[i]);
    const Vec3 up = -gravity.normalized();
    const Vec3 e1 = up.unitOrthogonal(), e2 = up.cross(e1);
    Vec3 normal_sum = Vec3::Zero();
    double mu = INFINITY;
    support.clear();
    for (const RestContact& contact : rest_contacts[i]) {
      const btCollisionObject* other = contact.other;
      const bool below = contact.normal.dot(up) > kFromBelow;
      if (other && is_moving(other)) {
        const int j = moving_index.at(other);
        if (!may_rest[j]) return false;  // something that moves touches it
        if (!below) continue;            // a resting body beside or on top of it
        if (!held[j]) return std::nullopt;
      } else if (other && other->isKinematicObject()) {
        return false;
      }
      if (!below) continue;  // a wall beside it
      normal_sum += contact.normal;
      mu = std::min(mu, contact.friction);
      support.emplace_back(contact.point.dot(e1), contact.point.dot(e2));
    }
    if (support.empty()) return false;
    // Gravity within the friction cone of the supports' mean normal.
    const Vec3 normal = normal_sum.normalized();
    if (up.cross(normal).norm() > mu * up.dot(normal)) return false;
    // The centre of mass over the support.
    const Vec3& centre = state.poses.back().position;
    return within_hull(support, Eigen::Vector2d(centre.dot(e1), centre.dot(e2)),
                       0.02 * state.radius);
  }

  // The rest guard (before write_back): bodies that stand at rest keep their pose, and their
  // history becomes that pose, so the network next sees a body at rest. Bodies are decided from
  // the ground up: a body on a slow body is decided once that body is.
  bool hold_resting_bodies(btCollisionWorld& world) {
    if (!options.rest_guard || networked.empty()) return false;
    may_rest.assign(moving.size(), 0);
    if (rest_contacts.size() < moving.size()) rest_contacts.resize(moving.size());
    find_rest_contacts(world);
    for (const int i : networked) {
      // Pushed bodies move as the push says; bodies in free flight touch nothing.
      may_rest[i] = !pushed.count(moving[i]) && slow_enough(i);
    }
    for (bool changed = true; changed;) {
      changed = false;
      for (const int i : networked) {
        if (!may_rest[i] || held[i]) continue;
        const std::optional<bool> decided = stands(i);
        if (!decided) continue;
        if (*decided) {
          held[i] = 1;
        } else {
          may_rest[i] = 0;  // the model moves it: what it touches cannot rest on it
        }
        changed = true;
      }
    }
    // Every body not held moves, undecided ones (resting on each other) included. A body held
    // before a body it touches was found to move is left to the model too, and so, in turn, is
    // what stands on it.
    for (const int i : networked) may_rest[i] = held[i];
    for (bool changed = true; changed;) {
      changed = false;
      for (const int i : networked) {
        if (!held[i]) continue;
        for (const RestContact& contact : rest_contacts[i]) {
          if (!contact.other || !is_moving(contact.other)) continue;
          if (may_rest[moving_index.at(contact.other)]) continue;
          held[i] = may_rest[i] = 0;
          changed = true;
          break;
        }
      }
    }
    for (const int i : networked) {
      if (!held[i]) continue;
      BodyState& state = states[moving[i]];
      std::fill(state.poses.begin(), state.poses.end(), Pose(state.poses.back()));
      in_network[i] = 0;
      ++stats.rested_bodies;
    }
    return stats.rested_bodies > 0;
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
                          std::make_unique<ModelPredictor>(
                              model, PredictionOptions{.threads = options.threads,
                                                       .turns = options.turns,
                                                       .mirror = options.mirror,
                                                       .fit_masses = options.fit_masses}),
                          model->config().graph, model->config().time_step, model->config().gravity,
                          with_model_budget(options, model->config())) {
  impl_->model_config = model->config();
}

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
  if (const auto* model = dynamic_cast<const ModelPredictor*>(impl_->predictor.get())) {
    impl_->share_search = same_contact_search(model->builder().config(), graph);
  }
  impl_->floor_patch = make_floor_mesh(graph.floor_half_extent, graph.floor_segments);
  for (const auto& [name, value] :
       {std::pair("penetration_tolerance", options.penetration_tolerance),
        std::pair("rest_contact_distance", options.rest_contact_distance)}) {
    if (value < 0 || !std::isfinite(value)) {
      throw ConfigError(
          fmt::format("FIGNetDynamicsWorld: {} is {} m; it must be finite and >= 0", name, value));
    }
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
  impl.pushed.clear();
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
      impl.pushed.insert(body);
    }
    if (body->getTotalTorque().length() > 0) {
      impl.pushed.insert(body);
      body->setAngularVelocity(body->getAngularVelocity() + body->getInvInertiaTensorWorld() *
                                                                body->getTotalTorque() * time_step);
    }
  }
  updateAabbs();
  computeOverlappingPairs();
  impl.collect_pairs_and_islands(*this);
  impl.collect_moving();
  impl.choose_network_bodies(*this);
  impl.stats.prepare_seconds = seconds_since(start);

  const auto predict_start = Clock::now();
  impl.advance();
  impl.guard_fast_bodies(*this);
  impl.guard_energy();
  impl.stats.predict_seconds = seconds_since(predict_start);

  const auto write_start = Clock::now();
  impl.write_back();
  impl.recover_static_penetrations(*this);
  impl.record_kinematic_poses(*this);
  impl.record_face_lines();
  impl.stats.write_back_seconds = seconds_since(write_start);
  const int networked = static_cast<int>(impl.networked.size());
  impl.stats.simulated_bodies = networked;
  impl.stats.free_flight_bodies =
      static_cast<int>(impl.moving.size()) - networked - impl.stats.rested_bodies;
  impl.stats.sleeping_bodies = static_cast<int>(impl.dynamic_bodies.size() - impl.moving.size());
  impl.stats.kinematic_objects = static_cast<int>(impl.scene.objects.size()) - networked;
  impl.stats.candidate_pairs = static_cast<int>(impl.candidates.size());
  impl.stats.face_edges = networked > 0 ? impl.predictor->last_face_edges() : 0;
  for (int k = 0; k < networked; ++k) {
    impl.stats.unfamiliar_bodies +=
        !familiar_material(impl.scene.objects[k].properties, impl.model_config);
  }
  impl.stats.unfamiliar_floor =
      networked > 0 && impl.scene.floor && !familiar_floor(*impl.scene.floor, impl.model_config);
  impl.stats.mesh_nodes = networked > 0 ? static_cast<int>(impl.scene.num_nodes()) : 0;
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
