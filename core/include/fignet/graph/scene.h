// The input of one graph: rigid objects with their rest meshes, recent position history, static
// properties and kinematic flags. Core never sees Bullet: adapters fill this struct.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <span>
#include <vector>

#include "fignet/geometry/mesh.h"

namespace fignet {

struct StaticProperties {
  double mass = 1.0;  // kg; 0 marks kinematic bodies (the pusher, the floor)
  double friction = 0.5;
  double restitution = 0.5;
};

struct Pose {
  Vec3 position = Vec3::Zero();  // centre of mass in the world frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();

  Vec3 apply(const Vec3& local) const { return position + orientation * local; }
};

struct SceneObject {
  // Rest mesh, its vertices in the body's centre-of-mass frame. Not owned; must outlive builds.
  const TriangleMesh* mesh = nullptr;
  // Node positions at steps t-h … t, oldest first, stacked: ((h+1)·V) x 3.
  Points positions;
  // Centre of mass at steps t-h … t, oldest first: (h+1) x 3.
  Points centers;
  StaticProperties properties;
  bool kinematic = false;
  // Kinematic objects only: node positions and centre of mass at step t+1.
  Points next_positions;
  Vec3 next_center = Vec3::Zero();

  int num_steps() const {
    return mesh ? static_cast<int>(positions.rows() / mesh->num_vertices()) : 0;
  }
  // Positions of all nodes at history step k (0 = oldest, h = current).
  auto positions_at(int k) const {
    return positions.middleRows(static_cast<Eigen::Index>(k) * mesh->num_vertices(),
                                mesh->num_vertices());
  }
};

// The mesh's rest vertices moved by `pose` (world frame).
Points posed_vertices(const TriangleMesh& mesh, const Pose& pose);

// Fills positions/centers from rigid poses (oldest first) and, for kinematic objects, the
// next pose. Reuses the object's buffers.
void set_pose_history(SceneObject& object, std::span<const Pose> poses,
                      const std::optional<Pose>& next_pose = std::nullopt);

struct Floor {
  double height = 0.0;                         // the floor is the plane z = height, normal +z
  StaticProperties properties{0.0, 0.3, 0.5};  // Kubric's floor: friction 0.3, restitution 0.5
  // Where the floor mesh (FloorModel::kMesh, GraphConfig::floor_half_extent around this point)
  // is centred in x and y: the origin in training; a physics engine moves it under bodies far
  // from the origin.
  double center_x = 0.0, center_y = 0.0;
};

struct Scene {
  std::vector<SceneObject> objects;
  std::optional<Floor> floor;  // used when GraphConfig::floor is kMesh or kImplicit

  // The objects' mesh nodes (vertices) together: the rows of a per-node array of the scene (its
  // accelerations), which a mesh floor's nodes never join.
  Eigen::Index num_nodes() const;
};

// Turns every object's positions, centres and kinematic next poses by `angle` radians about the
// vertical axis through the floor's centre (the origin when the scene has no floor). Gravity and
// the floor are unchanged by the turn, so the turned scene is as true as the original.
void turn_about_vertical(double angle, Scene& scene);

// Applies `map`, a turn about the vertical possibly after a reflection through a vertical plane
// (an orthogonal 3×3 matrix that keeps +z), to every object's positions, centres and kinematic
// next poses, about the vertical axis through the floor's centre (the origin when the scene has
// no floor). The objects' meshes are left as they are: a reflected scene needs its bodies' meshes
// mirrored too (mirrored_mesh), which the caller owns.
void map_about_vertical(const Eigen::Matrix3d& map, Scene& scene);

}  // namespace fignet
