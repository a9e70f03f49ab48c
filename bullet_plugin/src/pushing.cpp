#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "fignet/bullet/movi.h"
#include "fignet/error.h"
#include "fignet/geometry/shapes.h"

namespace fignet::bullet {

namespace {

constexpr double kPi = std::numbers::pi;

// Counter-clockwise outline of one of the pushed shapes, star-shaped about the origin.
std::vector<Eigen::Vector2d> outline(int kind, double size, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> aspect(0.6, 1.0);
  std::vector<Eigen::Vector2d> points;
  const double a = size / 2, b = a * aspect(rng);
  switch (kind) {
    case 0:  // rectangle
      points = {{-a, -b}, {a, -b}, {a, b}, {-a, b}};
      break;
    case 1:  // isosceles triangle of height 2b, centred on its centroid (a third of the way up)
      points = {{-a, -2 * b / 3}, {a, -2 * b / 3}, {0, 4 * b / 3}};
      break;
    case 2:  // ellipse
      for (int i = 0; i < 24; ++i) {
        points.emplace_back(a * std::cos(2 * kPi * i / 24), b * std::sin(2 * kPi * i / 24));
      }
      break;
    default:  // regular hexagon
      for (int i = 0; i < 6; ++i) {
        points.emplace_back(a * std::cos(2 * kPi * i / 6), a * std::sin(2 * kPi * i / 6));
      }
  }
  return points;
}

const char* kNames[] = {"rectangle", "triangle", "ellipse", "hexagon"};

}  // namespace

SceneSpec sample_pushing_scene(const MoviOptions& options, std::uint64_t seed) {
  if (!options.assets.empty()) {
    throw ConfigError("preset pushing pushes procedural prisms: assets need movi-b or movi-c");
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SceneSpec spec;
  spec.seed = seed;
  spec.physics_step = 1.0 / 250.0;
  spec.steps_per_frame = 3;
  spec.frames = frames_or_default(options, 125 / 3 + 1);
  spec.collision_margin = 0.0005;
  spec.floor = Floor{0.0, {0.0, 0.25, 0.0}};
  const double half_thickness = 0.01;

  // The pushed object: a prism resting on the support plane, random yaw.
  const int kind = static_cast<int>(unit(rng) * 4) % 4;
  const double size = 0.04 + 0.04 * unit(rng);
  const auto polygon = outline(kind, size, rng);
  BodySpec object = make_body(make_prism(kNames[kind], polygon, half_thickness), 1000.0, 0.25, 0.0);
  const double yaw = 2 * kPi * unit(rng);
  object.pose.orientation = Eigen::AngleAxisd(yaw, Vec3::UnitZ());
  object.pose.position = Vec3(0, 0, half_thickness);

  // The pusher: aimed at a point of the object's outline, from outside it, at an angle.
  const Eigen::Vector2d target =
      polygon[static_cast<size_t>(unit(rng) * polygon.size()) % polygon.size()] *
      (0.5 + 0.5 * unit(rng));
  const double approach = yaw + std::atan2(target.y(), target.x()) + kPi +
                          (unit(rng) - 0.5) * (kPi / 3);  // toward the centre, ±30°
  const Vec3 direction(-std::cos(approach), -std::sin(approach), 0.0);
  const Vec3 aim = object.pose.orientation * Vec3(target.x(), target.y(), 0.0);
  const double radius = 0.005, start_gap = 0.002 + 0.008 * unit(rng);
  // Start where the line of approach leaves the object's bounding circle (grown by the pusher's
  // radius), plus a small gap: contact comes within the first centimetres of the push.
  double bound = 0.0;
  for (const auto& p : polygon) bound = std::max(bound, p.norm());
  bound += radius;
  const Eigen::Vector2d p(aim.x(), aim.y()), back(-direction.x(), -direction.y());
  const double along = p.dot(back);
  const double reach = -along + std::sqrt(along * along - p.squaredNorm() + bound * bound);
  BodySpec pusher = make_body(make_cylinder(radius, 0.02, 16), 1.0, 0.25, 0.0);
  pusher.kinematic = true;
  pusher.properties.mass = 0.0;  // mass 0 marks the controlled pusher (seed B.2)
  pusher.pose.position = Vec3(aim.x(), aim.y(), 0.02 + 0.001) - direction * (reach + start_gap);
  pusher.linear_velocity = direction * (0.05 + 0.10 * unit(rng));
  spec.bodies = {object, pusher};
  return spec;
}

}  // namespace fignet::bullet
