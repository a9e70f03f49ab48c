#include "fignet/rollout/metrics.h"

#include <cmath>
#include <numbers>

#include "fignet/geometry/triangle_distance.h"
#include "fignet/graph/contacts.h"

namespace fignet {

double rotation_angle_degrees(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  const Eigen::Quaterniond relative = a.normalized().conjugate() * b.normalized();
  const double half = std::asin(std::min(1.0, relative.vec().norm()));
  return 2.0 * half * 180.0 / std::numbers::pi;
}

RolloutErrors rollout_errors(const Trajectory& predicted, const Trajectory& truth,
                             int first_predicted) {
  RolloutErrors errors;
  const int frames = std::min(predicted.num_frames(), truth.num_frames());
  errors.translation.assign(frames, 0.0);
  errors.rotation.assign(frames, 0.0);
  int predicted_frames = 0;
  for (int f = 0; f < frames; ++f) {
    double squared = 0.0, angle = 0.0;
    int dynamic = 0;
    for (size_t o = 0; o < truth.objects.size(); ++o) {
      if (truth.objects[o].kinematic) continue;
      const Pose& p = predicted.objects[o].poses[f];
      const Pose& t = truth.objects[o].poses[f];
      squared += (p.position - t.position).squaredNorm();
      angle += rotation_angle_degrees(p.orientation, t.orientation);
      ++dynamic;
      if (f >= first_predicted && f > 0) {
        errors.predicted_travel += (p.position - predicted.objects[o].poses[f - 1].position).norm();
        errors.true_travel += (t.position - truth.objects[o].poses[f - 1].position).norm();
      }
    }
    if (dynamic == 0) continue;
    errors.translation[f] = std::sqrt(squared / dynamic);
    errors.rotation[f] = angle / dynamic;
    if (f >= first_predicted) {
      errors.mean_translation += errors.translation[f];
      errors.mean_rotation += errors.rotation[f];
      ++predicted_frames;
    }
  }
  if (predicted_frames > 0) {
    errors.mean_translation /= predicted_frames;
    errors.mean_rotation /= predicted_frames;
    errors.final_translation = errors.translation.back();
    errors.final_rotation = errors.rotation.back();
  }
  return errors;
}

namespace {

// Generalised winding number of a closed mesh around p: 1 inside, 0 outside.
double winding_number(const Eigen::Ref<const Points>& vertices, const Triangles& faces,
                      const Vec3& p) {
  double solid_angle = 0.0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Vec3 a = vertices.row(faces(f, 0)).transpose() - p;
    const Vec3 b = vertices.row(faces(f, 1)).transpose() - p;
    const Vec3 c = vertices.row(faces(f, 2)).transpose() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    solid_angle += 2.0 * std::atan2(numerator, denominator);
  }
  return solid_angle / (4.0 * std::numbers::pi);
}

double distance_to_surface(const Eigen::Ref<const Points>& vertices, const Triangles& faces,
                           const Vec3& p) {
  double best = INFINITY;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Triangle t{{vertices.row(faces(f, 0)).transpose(), vertices.row(faces(f, 1)).transpose(),
                      vertices.row(faces(f, 2)).transpose()}};
    best = std::min(best, (closest_point_on_triangle(p, t) - p).norm());
  }
  return best;
}

}  // namespace

Penetration measure_penetration(const Trajectory& trajectory, int frame) {
  Penetration result;
  std::vector<Points> posed(trajectory.objects.size());
  std::vector<PosedMesh> meshes;
  for (size_t o = 0; o < trajectory.objects.size(); ++o) {
    const TrajectoryObject& object = trajectory.objects[o];
    posed[o] = posed_vertices(*object.mesh, object.poses[frame]);
    meshes.push_back({object.mesh.get(), posed[o].data(), object.kinematic});
  }
  ContactFinder finder;
  finder.update(meshes, false);
  std::vector<ObjectPair> pairs;
  std::vector<FacePair> faces;
  finder.find_all_face_pairs(0.0, pairs, faces);
  result.intersecting_face_pairs = static_cast<int>(faces.size());
  // Depth of every vertex inside another object of an overlapping pair.
  for (const ObjectPair& pair : pairs) {
    for (auto [inner, outer] : {std::pair(pair.a, pair.b), std::pair(pair.b, pair.a)}) {
      const Aabb& box = finder.bounds(outer);
      const Triangles& outer_faces = trajectory.objects[outer].mesh->faces();
      for (Eigen::Index i = 0; i < posed[inner].rows(); ++i) {
        const Vec3 p = posed[inner].row(i).transpose();
        if ((p.array() < box.min.array()).any() || (p.array() > box.max.array()).any()) continue;
        if (winding_number(posed[outer], outer_faces, p) > 0.5) {
          result.depth += distance_to_surface(posed[outer], outer_faces, p);
        }
      }
    }
  }
  if (trajectory.floor) {
    for (size_t o = 0; o < posed.size(); ++o) {
      if (trajectory.objects[o].kinematic) continue;
      result.depth += (trajectory.floor->height - posed[o].col(2).array()).cwiseMax(0.0).sum();
    }
  }
  return result;
}

PenetrationTotals& PenetrationTotals::operator+=(const PenetrationTotals& other) {
  predicted_depth += other.predicted_depth, truth_depth += other.truth_depth;
  predicted_count += other.predicted_count, truth_count += other.truth_count;
  return *this;
}

PenetrationRatio PenetrationTotals::ratio() const {
  auto divide = [](double a, double b) { return b > 0 ? a / b : std::nan(""); };
  return {divide(predicted_depth, truth_depth), divide(predicted_count, truth_count)};
}

PenetrationTotals penetration_totals(const Trajectory& predicted, const Trajectory& truth,
                                     int first) {
  PenetrationTotals totals;
  const int frames = std::min(predicted.num_frames(), truth.num_frames());
  for (int f = first; f < frames; ++f) {
    const Penetration p = measure_penetration(predicted, f), t = measure_penetration(truth, f);
    totals +=
        {p.depth, t.depth, double(p.intersecting_face_pairs), double(t.intersecting_face_pairs)};
  }
  return totals;
}

PenetrationRatio penetration_ratio(const Trajectory& predicted, const Trajectory& truth,
                                   int first) {
  return penetration_totals(predicted, truth, first).ratio();
}

}  // namespace fignet
