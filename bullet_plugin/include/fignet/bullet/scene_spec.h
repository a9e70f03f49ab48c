// A physics scene described independently of any engine: bodies (rest mesh in the principal
// centre-of-mass frame, material, initial pose and velocity, kinematic flag), floor, gravity and
// timing. The generator, native Bullet and FIGNetDynamicsWorld are all built from the same spec,
// so they always see the same bodies.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "fignet/bullet/mesh_import.h"
#include "fignet/data/trajectory.h"

namespace fignet::bullet {

struct BodySpec {
  std::shared_ptr<const TriangleMesh> mesh;  // principal centre-of-mass frame
  // Bullet's collision shape as convex pieces (same frame); empty: the hull of the mesh. One
  // piece: the hull of other points than the mesh's (a mesh simplified for the graph).
  std::vector<Points> convex_parts;
  StaticProperties properties;                        // mass = density × volume (0 when kinematic)
  Eigen::Vector3d inertia = Eigen::Vector3d::Ones();  // principal moments, kg·m²
  bool kinematic = false;
  Pose pose;
  Vec3 linear_velocity = Vec3::Zero(), angular_velocity = Vec3::Zero();
};

struct SceneSpec {
  std::vector<BodySpec> bodies;
  std::optional<Floor> floor;
  Vec3 gravity = Vec3(0, 0, -10);
  double physics_step = 1.0 / 240.0;  // seconds per Bullet step
  int steps_per_frame = 5;            // 240 Hz / 5 = 48 Hz frames
  int frames = 96;
  std::uint64_t seed = 0;
  double collision_margin = 0.005;  // metres around convex hulls (small scenes need less)

  double frame_step() const { return physics_step * steps_per_frame; }
};

// Mass, centre of mass and inertia tensor about the centre of mass, in a mesh's frame.
struct BodyInertia {
  double mass = 0.0;
  Vec3 center_of_mass = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

// A body made from `mesh` in any frame: the mesh is moved to its principal centre-of-mass frame
// (Bullet needs a diagonal inertia) and `pose` is set to where that frame lies in the mesh's
// frame, so the body sits where the mesh was until the caller moves it. `convex_parts` (in the
// mesh's frame) describe a non-convex mesh as a union of convex pieces.
BodySpec make_body(const TriangleMesh& mesh, const BodyInertia& inertia, double friction,
                   double restitution, const std::vector<Points>& convex_parts = {});
// The same with the mass properties of the closed mesh at `density`.
BodySpec make_body(const TriangleMesh& mesh, double density, double friction, double restitution,
                   const std::vector<Points>& convex_parts = {});

struct BodyMaterial {
  double density = 1000.0;  // kg/m³ (kg/m² for shell inertia); ignored when mass is set
  std::optional<double> mass;
  double friction = 0.5, restitution = 0.0;
};

// A body from a mesh in any frame, as it comes: cleaned, repaired and simplified for the graph
// by `options` (one warning line says what a mesh needed), convex or split into convex parts by
// HACD for Bullet, mass and inertia from the material and `options.inertia`. Throws MeshError or
// ConfigError naming the mesh.
BodySpec make_body(const TriangleMesh& mesh, const BodyMaterial& material,
                   const MeshImportOptions& options = {});

// One call from a mesh file (OBJ, STL, PLY, glTF, OFF through assimp) to a body: the mesh scaled
// by `scale`, then as make_body above. Throws FileError or MeshError naming the file.
BodySpec load_body(const std::filesystem::path& mesh_file, const BodyMaterial& material,
                   double scale = 1.0, const MeshImportOptions& options = {});

}  // namespace fignet::bullet
