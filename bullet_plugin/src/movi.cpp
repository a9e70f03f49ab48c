#include "fignet/bullet/movi.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <map>
#include <mutex>
#include <random>

#include "fignet/error.h"
#include "fignet/geometry/shapes.h"

namespace fignet::bullet {

namespace {

struct Material {
  double friction, restitution, density;
};
constexpr Material kMetal{0.4, 0.3, 2.7};
constexpr Material kRubber{0.8, 0.7, 1.1};

// One unit-scale body per (shape, material), shared by every scene of the process.
const BodySpec& unit_body(const std::string& shape, const Material& material) {
  static std::mutex mutex;
  static std::map<std::pair<std::string, double>, BodySpec> cache;
  const std::lock_guard lock(mutex);
  auto it = cache.find({shape, material.density});
  if (it == cache.end()) {
    it = cache
             .emplace(std::pair(shape, material.density),
                      make_body(make_movi_shape(shape), material.density, material.friction,
                                material.restitution, movi_convex_parts(shape)))
             .first;
  }
  return it->second;
}

// The unit body scaled by s: lengths × s, mass × s³, inertia × s⁵.
BodySpec scaled_body(const BodySpec& unit, double s) {
  BodySpec body = unit;
  body.mesh = std::make_shared<const TriangleMesh>(unit.mesh->name(), unit.mesh->vertices() * s,
                                                   unit.mesh->faces());
  for (Points& part : body.convex_parts) part *= s;
  body.properties.mass *= s * s * s;
  body.inertia *= s * s * s * s * s;
  return body;
}

}  // namespace

const std::vector<std::string>& movi_presets() {
  static const std::vector<std::string> presets = {"movi-a", "movi-b", "pushing"};
  return presets;
}

int frames_or_default(const MoviOptions& options, int preset_frames) {
  if (options.frames != 0 && options.frames < 2) {
    throw ConfigError(fmt::format("frames = {} (needs >= 2)", options.frames));
  }
  return options.frames ? options.frames : preset_frames;
}

SceneSpec sample_scene(const MoviOptions& options, std::uint64_t seed) {
  if (options.preset == "pushing") return sample_pushing_scene(options, seed);
  return sample_movi_scene(options, seed);
}

SceneSpec sample_movi_scene(const MoviOptions& options, std::uint64_t seed) {
  const bool movi_b = options.preset == "movi-b";
  if (options.preset != "movi-a" && !movi_b) {
    throw ConfigError(fmt::format("unknown scene preset '{}'; available: {}", options.preset,
                                  fmt::join(movi_presets(), ", ")));
  }
  if (options.min_objects < 1 || options.max_objects < options.min_objects) {
    throw ConfigError(fmt::format("objects range {}..{} is empty or below 1", options.min_objects,
                                  options.max_objects));
  }
  SceneSpec spec;
  spec.seed = seed;
  spec.frames = frames_or_default(options, 96);
  spec.floor = Floor{0.0, {0.0, 0.3, 0.5}};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  // MOVi-A: cube, cylinder, sphere at scale 0.7 or 1.4; MOVi-B: all eight shapes, scale
  // U(0.7, 1.4).
  const std::vector<std::string>& all_shapes = movi_shape_names();
  const int shape_count = movi_b ? static_cast<int>(all_shapes.size()) : 3;
  const int count = options.min_objects +
                    static_cast<int>(unit(rng) * (options.max_objects - options.min_objects + 1));
  std::vector<std::pair<Vec3, double>> spheres;  // placed bodies' bounding spheres
  for (int i = 0; i < std::min(count, options.max_objects); ++i) {
    const std::string& shape = all_shapes[static_cast<int>(unit(rng) * shape_count) % shape_count];
    const double scale = movi_b ? 0.7 + 0.7 * unit(rng) : (unit(rng) < 0.5 ? 0.7 : 1.4);
    BodySpec body = scaled_body(unit_body(shape, unit(rng) < 0.5 ? kMetal : kRubber), scale);
    const double radius = body.mesh->vertices().rowwise().norm().maxCoeff();
    bool placed = false;
    for (int attempt = 0; attempt < 100 && !placed; ++attempt) {
      body.pose.orientation =
          Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
      body.pose.position = Vec3(-5 + 10 * unit(rng), -5 + 10 * unit(rng), 1 + 4 * unit(rng));
      const double lowest =
          (body.mesh->vertices() * body.pose.orientation.toRotationMatrix().transpose())
              .col(2)
              .minCoeff();
      placed = body.pose.position.z() + lowest > spec.floor->height;
      for (const auto& [center, r] : spheres) {
        placed = placed && (center - body.pose.position).norm() > r + radius;
      }
    }
    if (!placed) continue;  // no free spot in 100 tries: the scene gets one object fewer
    const Vec3 target(-4 + 8 * unit(rng), -4 + 8 * unit(rng), 0.0);
    body.linear_velocity = target - Vec3(body.pose.position.x(), body.pose.position.y(), 0.0);
    spheres.emplace_back(body.pose.position, radius);
    spec.bodies.push_back(std::move(body));
  }
  return spec;
}

}  // namespace fignet::bullet
