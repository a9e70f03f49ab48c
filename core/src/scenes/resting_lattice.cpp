#include "fignet/scenes/resting_lattice.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <random>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"

namespace fignet {

RestingLattice make_resting_lattice(const RestingLatticeOptions& options) {
  if (options.objects < 1) {
    throw ConfigError(fmt::format("resting lattice: objects = {} (must be >= 1)", options.objects));
  }
  if (options.history < 1) {
    throw ConfigError(fmt::format("resting lattice: history = {} (must be >= 1)", options.history));
  }
  if (options.shapes.empty() || options.scales.empty()) {
    throw ConfigError("resting lattice: needs at least one shape and one scale");
  }
  RestingLattice lattice;
  // One centred, scaled mesh per (shape, scale), shared by the objects that use it.
  std::map<std::pair<std::string, double>, const TriangleMesh*> cache;
  double max_radius = 0.0;
  for (const std::string& shape : options.shapes) {
    const TriangleMesh unit = centered_on_center_of_mass(make_movi_shape(shape));
    for (double scale : options.scales) {
      if (!(scale > 0.0)) throw ConfigError(fmt::format("resting lattice: scale {} <= 0", scale));
      Points vertices = unit.vertices() * scale;
      max_radius = std::max(max_radius, vertices.rowwise().norm().maxCoeff());
      auto mesh = std::make_unique<TriangleMesh>(shape, std::move(vertices), unit.faces());
      cache[{shape, scale}] = mesh.get();
      lattice.meshes.push_back(std::move(mesh));
    }
  }

  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<size_t> pick_shape(0, options.shapes.size() - 1);
  std::uniform_int_distribution<size_t> pick_scale(0, options.scales.size() - 1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const int side = static_cast<int>(std::ceil(std::sqrt(options.objects)));
  const double spacing = 2.0 * max_radius + options.gap;
  const int steps = options.history + 1;

  for (int i = 0; i < options.objects; ++i) {
    SceneObject object;
    object.mesh = cache[{options.shapes[pick_shape(rng)], options.scales[pick_scale(rng)]}];
    Pose pose;
    pose.orientation =
        Eigen::Quaterniond(Eigen::Vector4d(uniform(rng), uniform(rng), uniform(rng), uniform(rng)))
            .normalized();
    // Lowest vertex half a gap above the floor, centred on its lattice cell.
    const Points rotated =
        object.mesh->vertices() * pose.orientation.toRotationMatrix().transpose();
    const double lowest = rotated.col(2).minCoeff();
    pose.position = Vec3((i % side - 0.5 * (side - 1)) * spacing,
                         (i / side - 0.5 * (side - 1)) * spacing, options.gap / 2 - lowest);
    // A small drift with a slow spin, so velocity features are not all zero.
    const Vec3 velocity = options.speed * Vec3(uniform(rng), uniform(rng), 0.0);
    const Vec3 spin = 0.5 * Vec3(uniform(rng), uniform(rng), uniform(rng));
    std::vector<Pose> history(steps);
    for (int k = 0; k < steps; ++k) {
      const double t = (k - (steps - 1)) * options.time_step;  // <= 0: the current pose is last
      history[k].position = pose.position + t * velocity;
      const Vec3 angle = t * spin;
      history[k].orientation =
          (angle.norm() > 0
               ? Eigen::Quaterniond(Eigen::AngleAxisd(angle.norm(), angle.normalized()))
               : Eigen::Quaterniond::Identity()) *
          pose.orientation;
    }
    set_pose_history(object, history);
    const auto volume = compute_mass_properties(*object.mesh).volume;
    object.properties = i % 2 ? StaticProperties{2.7 * volume, 0.4, 0.3}   // metal
                              : StaticProperties{1.1 * volume, 0.8, 0.7};  // rubber
    lattice.scene.objects.push_back(std::move(object));
  }
  lattice.scene.floor = Floor{};
  return lattice;
}

}  // namespace fignet
