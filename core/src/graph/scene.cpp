#include "fignet/graph/scene.h"

#include "fignet/error.h"

namespace fignet {

namespace {

void write_posed(const TriangleMesh& mesh, const Pose& pose, Eigen::Ref<Points> out) {
  const Eigen::Matrix3d rotation = pose.orientation.normalized().toRotationMatrix();
  out.noalias() = mesh.vertices() * rotation.transpose();
  out.rowwise() += pose.position.transpose();
}

}  // namespace

Points posed_vertices(const TriangleMesh& mesh, const Pose& pose) {
  Points out(mesh.num_vertices(), 3);
  write_posed(mesh, pose, out);
  return out;
}

void set_pose_history(SceneObject& object, std::span<const Pose> poses,
                      const std::optional<Pose>& next_pose) {
  if (object.mesh == nullptr) throw ConfigError("set_pose_history: the object has no mesh");
  if (poses.empty()) throw ConfigError("set_pose_history: needs at least one pose");
  const Eigen::Index v = object.mesh->num_vertices();
  object.positions.resize(v * static_cast<Eigen::Index>(poses.size()), 3);
  object.centers.resize(static_cast<Eigen::Index>(poses.size()), 3);
  for (size_t k = 0; k < poses.size(); ++k) {
    write_posed(*object.mesh, poses[k], object.positions.middleRows(v * k, v));
    object.centers.row(k) = poses[k].position.transpose();
  }
  if (next_pose) {
    object.next_positions.resize(v, 3);
    write_posed(*object.mesh, *next_pose, object.next_positions);
    object.next_center = next_pose->position;
  }
}

void turn_about_vertical(double angle, Scene& scene) {
  map_about_vertical(Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix(), scene);
}

void map_about_vertical(const Eigen::Matrix3d& map, Scene& scene) {
  const Vec3 axis =
      scene.floor ? Vec3(scene.floor->center_x, scene.floor->center_y, 0.0) : Vec3::Zero();
  // Row vectors map by p ↦ axis + M·(p − axis), i.e. (p − axis)·Mᵀ + axis.
  auto map_points = [&](Points& points) {
    if (points.rows() == 0) return;
    points = ((points.rowwise() - axis.transpose()) * map.transpose()).rowwise() + axis.transpose();
  };
  for (SceneObject& object : scene.objects) {
    map_points(object.positions);
    map_points(object.centers);
    if (object.kinematic) {
      map_points(object.next_positions);
      object.next_center = axis + map * (object.next_center - axis);
    }
  }
}

Eigen::Index Scene::num_nodes() const {
  Eigen::Index nodes = 0;
  for (const SceneObject& object : objects) nodes += object.mesh->num_vertices();
  return nodes;
}

}  // namespace fignet
