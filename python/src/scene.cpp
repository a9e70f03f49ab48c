// A scene API without Bullet in sight: bodies from vertices and faces (or mesh files), a floor,
// step(), poses out. Underneath it is the same BulletSimulation the tools use, with a
// FIGNetDynamicsWorld when a model is given (its free-flight, sleeping and guard options) and
// native Bullet at 240 Hz otherwise.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "bindings.h"
#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/bullet/mesh_file.h"
#include "fignet/bullet/scene_spec.h"
#include "fignet/error.h"
#include "fignet/geometry/mesh.h"
#include "fignet/rollout/predictor.h"

namespace fignet::python {

namespace {

using bullet::BodySpec;
using bullet::SceneSpec;

class PyScene {
 public:
  PyScene(std::shared_ptr<Model> model, bool free_flight, bool sleeping, bool penetration_guard,
          bool sweep_guard, int threads, std::optional<int> graph_vertices, bool rest_guard,
          int turns, bool energy_guard, bool seed_falling, bool mirror)
      : model_(std::move(model)) {
    // Checked now: the world, and with it the predictor, is made at the first step.
    PredictionOptions{.turns = turns}.validate();
    if (graph_vertices) options_.max_graph_vertices = *graph_vertices;
    options_.free_flight = free_flight;
    options_.sleeping = sleeping;
    options_.penetration_guard = penetration_guard;
    options_.sweep_guard = sweep_guard;
    options_.rest_guard = rest_guard;
    options_.energy_guard = energy_guard;
    options_.seed_falling = seed_falling;
    options_.threads = threads;
    options_.turns = turns;
    options_.mirror = mirror;
    if (model_) {
      // Frames at the model's step, Bullet's 240 Hz substeps for the native reference.
      spec_.gravity = model_->config().gravity;
      spec_.physics_step = model_->config().time_step / spec_.steps_per_frame;
    }
  }

  int add_body(const BodySpec& body, const py::handle& position, const py::handle& orientation,
               const py::handle& linear_velocity, const py::handle& angular_velocity) {
    require_not_started("add a body");
    BodySpec placed = body;
    // The caller places the mesh's own frame; the body's frame is its principal centre-of-mass
    // frame inside it.
    const Pose frame{to_vec3(position, "position"), to_quaternion(orientation, "orientation")};
    placed.pose.position = frame.apply(body.pose.position);
    placed.pose.orientation = (frame.orientation * body.pose.orientation).normalized();
    placed.linear_velocity = to_vec3(linear_velocity, "linear_velocity");
    placed.angular_velocity = to_vec3(angular_velocity, "angular_velocity");
    offsets_.push_back(body.pose);
    spec_.bodies.push_back(std::move(placed));
    return static_cast<int>(spec_.bodies.size()) - 1;
  }

  void add_floor(double height, double friction, double restitution) {
    require_not_started("add a floor");
    if (spec_.floor) throw ConfigError("the scene has a floor already");
    Floor floor;
    floor.height = height;
    floor.properties = {0.0, friction, restitution};
    spec_.floor = floor;
  }

  void step(int frames) {
    if (frames < 0) throw py::value_error(fmt::format("step: frames = {} (must be >= 0)", frames));
    if (spec_.bodies.empty()) throw ConfigError("step: the scene has no bodies (add_body first)");
    if (!simulation_) start();
    py::gil_scoped_release release;
    for (int f = 0; f < frames; ++f) simulation_->step_frame();
    frame_ += frames;
  }

  // Each body's mesh frame (what add_body placed), not its centre-of-mass frame.
  Pose mesh_pose(int body) const {
    const Pose com = learned_world_ ? learned_world_->precise_pose(*object(body))
                     : simulation_  ? simulation_->pose(body)
                                    : spec_.bodies[body].pose;
    const Pose& offset = offsets_[body];
    Pose out;
    out.orientation = (com.orientation * offset.orientation.conjugate()).normalized();
    out.position = com.position - out.orientation * offset.position;
    return out;
  }

  // Every body's mesh frame, in order.
  std::vector<Pose> mesh_poses() const {
    std::vector<Pose> poses(static_cast<size_t>(size()));
    for (int b = 0; b < size(); ++b) poses[b] = mesh_pose(b);
    return poses;
  }

  py::array_t<double> velocities(bool angular) const {
    py::array_t<double> out(std::vector<py::ssize_t>{size(), 3});
    for (int b = 0; b < size(); ++b) {
      const BodySpec& spec = spec_.bodies[b];
      const Vec3 v = simulation_ ? (angular ? simulation_->angular_velocity(b)
                                            : simulation_->linear_velocity(b))
                                 : (angular ? spec.angular_velocity : spec.linear_velocity);
      for (int c = 0; c < 3; ++c) out.mutable_at(b, c) = v[c];
    }
    return out;
  }

  py::dict last_step_stats() const {
    py::dict out;
    if (!learned_world_) return out;
    const bullet::FIGNetStepStats& s = learned_world_->last_step_stats();
    out["simulated_bodies"] = s.simulated_bodies;
    out["free_flight_bodies"] = s.free_flight_bodies;
    out["sleeping_bodies"] = s.sleeping_bodies;
    out["face_edges"] = s.face_edges;
    out["mesh_nodes"] = s.mesh_nodes;
    out["guarded_bodies"] = s.guarded_bodies;
    out["recovered_bodies"] = s.recovered_bodies;
    out["energy_bodies"] = s.energy_bodies;
    out["rested_bodies"] = s.rested_bodies;
    out["prepare_seconds"] = s.prepare_seconds;
    out["predict_seconds"] = s.predict_seconds;
    out["write_back_seconds"] = s.write_back_seconds;
    return out;
  }

  int size() const { return static_cast<int>(spec_.bodies.size()); }
  int frame() const { return frame_; }
  double time_step() const { return spec_.frame_step(); }
  bool learned() const { return model_ != nullptr; }
  const SceneSpec& spec() const { return spec_; }

 private:
  // Bullet's object of a body: bodies are added in spec order, the floor after them.
  const btCollisionObject* object(int body) const {
    return simulation_->world().getCollisionObjectArray()[body];
  }

  void require_not_started(const char* what) const {
    if (simulation_) {
      throw ConfigError(fmt::format(
          "cannot {} after the first step: a scene is built from its bodies when it starts", what));
    }
  }

  void start() {
    if (!model_) {
      simulation_ = std::make_unique<bullet::BulletSimulation>(spec_);
      return;
    }
    warn_of_unfamiliar_materials();
    bullet::SolverSettings one_step;
    one_step.steps_per_frame = 1;  // the network steps once per frame
    simulation_ = std::make_unique<bullet::BulletSimulation>(
        spec_, one_step,
        [this](btDispatcher* d, btBroadphaseInterface* b, btConstraintSolver* s,
               btCollisionConfiguration* c) {
          auto world = std::make_unique<bullet::FIGNetDynamicsWorld>(d, b, s, c, model_, options_);
          learned_world_ = world.get();
          return world;
        });
  }

  // One UserWarning naming the bodies, and the floor, whose friction or restitution lie outside
  // the model's training data: add_body's defaults are Bullet's (restitution 0), which no MOVi
  // material has, and there the network guesses (a resting body may slide).
  void warn_of_unfamiliar_materials() const {
    const ModelConfig& config = model_->config();
    std::vector<std::string> outside;
    for (size_t b = 0; b < spec_.bodies.size(); ++b) {
      const BodySpec& body = spec_.bodies[b];
      if (body.kinematic || familiar_material(body.properties, config)) continue;
      // add_body names an unnamed body "body <index>": said once.
      const std::string label = fmt::format("body {}", b);
      const std::string name =
          body.mesh->name() == label ? label : fmt::format("{} '{}'", label, body.mesh->name());
      outside.push_back(fmt::format("{} (friction {:g}, restitution {:g})", name,
                                    body.properties.friction, body.properties.restitution));
    }
    if (spec_.floor && !familiar_floor(*spec_.floor, config)) {
      outside.push_back(fmt::format("the floor (friction {:g}, restitution {:g})",
                                    spec_.floor->properties.friction,
                                    spec_.floor->properties.restitution));
    }
    if (outside.empty()) return;
    const size_t shown = std::min<size_t>(outside.size(), 4);
    const std::string more =
        outside.size() > shown ? fmt::format("; and {} more", outside.size() - shown) : "";
    const std::string line = fmt::format(
        "materials outside the model's training data, where it guesses: {}{}. The model saw "
        "bodies of friction {} and restitution {} (floor: friction {}, restitution {}); pass "
        "friction= and restitution= within them to add_body",
        fmt::join(outside.begin(), outside.begin() + shown, "; "), more, config.friction.text(),
        config.restitution.text(), config.floor_friction.text(), config.floor_restitution.text());
    py::module_::import("warnings")
        .attr("warn")(line, py::module_::import("builtins").attr("UserWarning"),
                      1);  // step()'s caller
  }

  std::shared_ptr<Model> model_;
  bullet::FIGNetWorldOptions options_;
  SceneSpec spec_;
  std::vector<Pose> offsets_;  // each body's centre-of-mass frame in its mesh's frame
  std::unique_ptr<bullet::BulletSimulation> simulation_;
  const bullet::FIGNetDynamicsWorld* learned_world_ = nullptr;  // owned by simulation_
  int frame_ = 0;
};

bullet::BodyMaterial material_of(std::optional<double> mass, double density, double friction,
                                 double restitution) {
  bullet::BodyMaterial material;
  material.mass = mass;
  material.density = density;
  material.friction = friction;
  material.restitution = restitution;
  return material;
}

// How meshes become bodies; what a mesh needed goes to Python's warnings (a UserWarning).
bullet::MeshImportOptions import_options(const std::string& inertia, int max_graph_vertices) {
  bullet::MeshImportOptions options;
  options.inertia = bullet::parse_mesh_inertia(inertia);
  options.max_graph_vertices = max_graph_vertices;
  options.warn = [](const std::string& line) {
    py::module_::import("warnings")
        .attr("warn")(line, py::module_::import("builtins").attr("UserWarning"), 3);
  };
  return options;
}

// A kinematic body: no mass, moved by its velocities alone.
BodySpec kinematic_body(const TriangleMesh& mesh, double friction, double restitution) {
  BodySpec body =
      bullet::make_body(mesh, bullet::BodyInertia{1.0, Vec3::Zero(), Eigen::Matrix3d::Identity()},
                        friction, restitution);
  body.kinematic = true;
  body.properties.mass = 0.0;
  return body;
}

}  // namespace

void bind_scene(py::module_& m) {
  const auto zeros = std::vector<double>{0, 0, 0};
  const auto identity = std::vector<double>{1, 0, 0, 0};
  py::class_<PyScene>(m, "Scene", R"(Rigid bodies stepped by a FIGNet model, or by native Bullet.

With a model, each frame is one learned step at the model's time step (1/48 s for MOVi-A):
bodies with nothing within the collision radius fly exactly under gravity (free_flight), resting
islands sleep as in Bullet (sleeping), and bodies that sink into the floor or other static bodies
are pushed out (penetration_guard), bodies that stand at rest stay where they are, by
Coulomb's static friction under gravity (rest_guard), and islands in contact do not gain
mechanical energy beyond a tenth of their kinetic energy (energy_guard); turn all five off for
the network alone, as `fignet eval` measures it. A mesh finer than the model was trained on enters the graph simplified to
`graph_vertices` (default None: the model's own resolution, 64 for MOVi-A; 0: never) within 2 %
of its size; Bullet still collides the full mesh. `turns` > 1 predicts each frame that
many times, the scene turned by k/turns of a turn about the vertical, and averages: it cancels the
sideways push a model gives resting bodies, at `turns` times the cost; `mirror` averages with
the scene seen in a mirror too, at each turn (twice the cost). A body added in free
flight starts on its gravity's parabola, as bodies in the training data moved (seed_falling;
False: moving straight at its velocity, which falls g·dt²/2 too far in the first step). Without a
model, native Bullet steps at 240 Hz, 5 substeps per frame.)")
      .def(py::init<std::shared_ptr<Model>, bool, bool, bool, bool, int, std::optional<int>, bool,
                    int, bool, bool, bool>(),
           py::arg("model") = py::none(), py::arg("free_flight") = true, py::arg("sleeping") = true,
           py::arg("penetration_guard") = true, py::arg("sweep_guard") = true,
           py::arg("threads") = 1, py::arg("graph_vertices") = py::none(),
           py::arg("rest_guard") = true, py::arg("turns") = 1, py::arg("energy_guard") = true,
           py::arg("seed_falling") = true, py::arg("mirror") = false)
      .def(
          "add_body",
          [](PyScene& scene, const py::handle& vertices, const py::handle& faces,
             std::optional<double> mass, double density, double friction, double restitution,
             const py::handle& position, const py::handle& orientation,
             const py::handle& linear_velocity, const py::handle& angular_velocity, bool kinematic,
             const std::string& name, const std::string& inertia, int max_graph_vertices) {
            const std::string label = name.empty() ? fmt::format("body {}", scene.size()) : name;
            const TriangleMesh mesh(label, to_points(vertices, "vertices"),
                                    to_triangles(faces, "faces"));
            const BodySpec body =
                kinematic
                    ? kinematic_body(mesh, friction, restitution)
                    : bullet::make_body(mesh, material_of(mass, density, friction, restitution),
                                        import_options(inertia, max_graph_vertices));
            return scene.add_body(body, position, orientation, linear_velocity, angular_velocity);
          },
          py::arg("vertices"), py::arg("faces"), py::arg("mass") = py::none(),
          py::arg("density") = 1000.0, py::arg("friction") = 0.5, py::arg("restitution") = 0.0,
          py::arg("position") = zeros, py::arg("orientation") = identity,
          py::arg("linear_velocity") = zeros, py::arg("angular_velocity") = zeros,
          py::arg("kinematic") = false, py::arg("name") = "", py::arg("inertia") = "auto",
          py::arg("max_graph_vertices") = 1000,
          R"(Adds a body from a triangle mesh: vertices (n, 3) in metres and faces (m, 3) of vertex
indices. Meshes as they come are accepted: coincident vertices are welded, windings made
consistent and outward, and an open or broken mesh is given to FIGNet as a closed alpha wrap; a
mesh with more than `max_graph_vertices` (0: no limit) is simplified for the graph. One
UserWarning says what a mesh needed. Mass in kg, or from `density` and `inertia`: "auto" (the
enclosed volume when closed, else the convex hull's), "volume", "convex", or "shell" (density in
kg/m² of surface).
`position` and `orientation` (w, x, y, z) place the mesh's own frame; velocities are those of the
centre of mass (m/s, rad/s). Kinematic bodies have no mass and move at their given velocities.
Returns the body's index.)")
      .def(
          "add_mesh_file",
          [](PyScene& scene, const std::filesystem::path& path, double scale,
             std::optional<double> mass, double density, double friction, double restitution,
             const py::handle& position, const py::handle& orientation,
             const py::handle& linear_velocity, const py::handle& angular_velocity,
             const std::string& inertia, int max_graph_vertices) {
            const BodySpec body =
                bullet::load_body(path, material_of(mass, density, friction, restitution), scale,
                                  import_options(inertia, max_graph_vertices));
            return scene.add_body(body, position, orientation, linear_velocity, angular_velocity);
          },
          py::arg("path"), py::arg("scale") = 1.0, py::arg("mass") = py::none(),
          py::arg("density") = 1000.0, py::arg("friction") = 0.5, py::arg("restitution") = 0.0,
          py::arg("position") = zeros, py::arg("orientation") = identity,
          py::arg("linear_velocity") = zeros, py::arg("angular_velocity") = zeros,
          py::arg("inertia") = "auto", py::arg("max_graph_vertices") = 1000,
          "Adds a body from a mesh file (OBJ, STL, PLY, glTF, OFF), scaled by `scale`; "
          "otherwise as add_body.")
      .def("add_floor", &PyScene::add_floor, py::arg("height") = 0.0, py::arg("friction") = 0.3,
           py::arg("restitution") = 0.5,
           "A static floor, the plane z = height (Kubric's friction and restitution by default).")
      .def("step", &PyScene::step, py::arg("frames") = 1,
           "Advances `frames` frames (the GIL is released meanwhile). Bodies cannot be added "
           "after the first step.")
      .def_property_readonly(
          "positions", [](const PyScene& s) { return positions_array(s.mesh_poses()); },
          "Where each body's mesh frame is (bodies, 3), metres.")
      .def_property_readonly(
          "quaternions", [](const PyScene& s) { return quaternions_array(s.mesh_poses()); },
          "Each body's mesh frame orientation (bodies, 4) as (w, x, y, z).")
      .def_property_readonly(
          "linear_velocities", [](const PyScene& s) { return s.velocities(false); },
          "Centre-of-mass velocities (bodies, 3), m/s.")
      .def_property_readonly(
          "angular_velocities", [](const PyScene& s) { return s.velocities(true); },
          "Angular velocities (bodies, 3), rad/s.")
      .def_property_readonly("num_bodies", &PyScene::size, "Bodies added (the floor apart).")
      .def_property_readonly("frame", &PyScene::frame, "Frames stepped so far.")
      .def_property_readonly("time_step", &PyScene::time_step, "Seconds per frame.")
      .def_property_readonly("learned", &PyScene::learned, "Whether a model steps the bodies.")
      .def("last_step_stats", &PyScene::last_step_stats,
           "What the model's last step simulated (bodies by kind, face–face edges, guards), or "
           "an empty dict without a model.")
      .def("__repr__", [](const PyScene& s) {
        return fmt::format("<fignet.Scene: {} bodies, {}, frame {}>", s.size(),
                           s.learned() ? "learned" : "native Bullet", s.frame());
      });
}

}  // namespace fignet::python
