#include "fignet/bullet/movi.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>
#include <random>

#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/mesh_file.h"
#include "fignet/error.h"
#include "fignet/geometry/shapes.h"
#include "fignet/graph/scene.h"

namespace fignet::bullet {

namespace {

struct Material {
  double friction, restitution, density;
};
constexpr Material kMetal{0.4, 0.3, 2.7};
constexpr Material kRubber{0.8, 0.7, 1.1};
constexpr Material kScanned{0.5, 0.5, 1.0};  // MOVi-C: every object

// What an object is made from: a MOVi shape by name, or a mesh file scaled so the largest side
// of its bounding box is `largest_side` (KuBasic shapes span 2 m, MOVi-C's assets 1 m).
struct Source {
  std::string name;
  bool file = false;
  double largest_side = 0.0;
};

// The body of `source` at unit scale and density 1; materials and scales are applied per object.
struct UnitGeometry {
  BodySpec body;
  int mass_scale_power = 3;  // shells: mass grows with area, not volume
};

UnitGeometry make_unit_geometry(const Source& source, const MeshImportOptions& options) {
  if (!source.file) {
    return {make_body(make_movi_shape(source.name), 1.0, 0.0, 0.0, movi_convex_parts(source.name))};
  }
  const TriangleMesh loaded = load_mesh_file(source.name);
  const Vec3 extent =
      loaded.vertices().colwise().maxCoeff() - loaded.vertices().colwise().minCoeff();
  const double scale = source.largest_side / extent.maxCoeff();
  const int power = options.inertia == MeshInertia::kShell ? 2 : 3;
  return {make_body(TriangleMesh(loaded.name(), loaded.vertices() * scale, loaded.faces()),
                    BodyMaterial{1.0, {}, 0.0, 0.0}, options),
          power};
}

// Shared by every scene of the process: a mesh file is loaded, repaired and decomposed once (and
// warned about once).
const UnitGeometry& unit_geometry(const Source& source, const MeshImportOptions& options) {
  static std::mutex mutex;
  static std::map<std::string, UnitGeometry> cache;
  const std::lock_guard lock(mutex);
  const std::string key = fmt::format(
      "{}|{}|{}|{}|{}|{}", source.name, source.largest_side, options.repair,
      options.max_graph_vertices, options.simplify_tolerance, mesh_inertia_name(options.inertia));
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, make_unit_geometry(source, options)).first;
  return it->second;
}

// The unit geometry made of `material` and scaled by s: lengths × s, mass × s³ and inertia × s⁵
// (s² and s⁴ for shells).
BodySpec make_object(const Source& source, const MeshImportOptions& options,
                     const Material& material, double s) {
  const UnitGeometry& unit = unit_geometry(source, options);
  BodySpec body = unit.body;
  body.mesh = std::make_shared<const TriangleMesh>(
      unit.body.mesh->name(), unit.body.mesh->vertices() * s, unit.body.mesh->faces());
  for (Points& part : body.convex_parts) part *= s;
  const double mass_scale = std::pow(s, unit.mass_scale_power);
  body.properties = {material.density * unit.body.properties.mass * mass_scale, material.friction,
                     material.restitution};
  body.inertia = material.density * unit.body.inertia * (mass_scale * s * s);
  return body;
}

// The mesh files of an asset folder, listed once per process.
const std::vector<std::filesystem::path>& asset_files(const std::filesystem::path& folder) {
  static std::mutex mutex;
  static std::map<std::filesystem::path, std::vector<std::filesystem::path>> cache;
  const std::lock_guard lock(mutex);
  auto it = cache.find(folder);
  if (it == cache.end()) it = cache.emplace(folder, list_mesh_files(folder)).first;
  return it->second;
}

using BoundingSpheres = std::vector<std::pair<Vec3, double>>;

bool clear_of(const BoundingSpheres& placed, const Vec3& center, double radius) {
  for (const auto& [other, other_radius] : placed) {
    if ((other - center).norm() <= other_radius + radius) return false;
  }
  return true;
}

// An object's scale and material as the preset draws them (one draw each): MOVi-A 0.7 or 1.4,
// MOVi-B U(0.7, 1.4), MOVi-C U(0.75, 3.0); metal or rubber, MOVi-C's scanned material.
double draw_scale(bool movi_a, bool movi_c, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return movi_a   ? (unit(rng) < 0.5 ? 0.7 : 1.4)
         : movi_c ? 0.75 + 2.25 * unit(rng)
                  : 0.7 + 0.7 * unit(rng);
}
const Material& draw_material(bool movi_c, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return movi_c ? kScanned : (unit(rng) < 0.5 ? kMetal : kRubber);
}

double bounding_radius(const BodySpec& body) {
  return body.mesh->vertices().rowwise().norm().maxCoeff();
}

// Moves `group` (built around the vertical axis through the origin) whole to a uniform spot in
// (−4,−4)–(4,4) where no body's bounding sphere meets one of `placed`, and appends its bodies to
// spec; left out after 100 tries.
void place_clear(std::vector<BodySpec>& group, std::mt19937_64& rng, SceneSpec& spec,
                 BoundingSpheres& placed) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int attempt = 0; attempt < 100; ++attempt) {
    const Vec3 spot(-4 + 8 * unit(rng), -4 + 8 * unit(rng), 0.0);
    bool clear = true;
    for (const BodySpec& body : group) {
      clear = clear && clear_of(placed, body.pose.position + spot, bounding_radius(body));
    }
    if (!clear) continue;
    for (BodySpec& body : group) {
      body.pose.position += spot;
      placed.emplace_back(body.pose.position, bounding_radius(body));
      spec.bodies.push_back(std::move(body));
    }
    return;
  }
}

// A horizontal shift off a support's axis, uniform over the disc of a tenth of the narrower
// half-width: the centre of mass stays well inside the support, so what rests on it stands.
Vec3 off_axis_shift(double half_width, double support_half_width, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double reach = 0.1 * std::min(half_width, support_half_width) * std::sqrt(unit(rng));
  const double angle = 2.0 * std::numbers::pi * unit(rng);
  return Vec3(reach * std::cos(angle), reach * std::sin(angle), 0.0);
}

// A MOVi sphere of the preset's scales and materials resting still on the flat top (at height
// `support_top`) of a stack's top level, centred at `support_center`, at the collision margin, on a
// facet drawn uniformly: turned so that facet faces straight down (each facet of a sphere mesh
// holds the centre of mass above it, so Bullet holds it there), then by a uniform angle about the
// vertical, and shifted off the support's axis as a stack's levels are.
BodySpec sphere_on_top(const Vec3& support_center, double support_half_width, double support_top,
                       const MoviOptions& options, bool movi_a, double margin,
                       std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double scale = draw_scale(movi_a, false, rng);
  const Material& material = draw_material(false, rng);
  BodySpec sphere = make_object({"sphere"}, options.mesh_import, material, scale);
  const Eigen::Index faces = sphere.mesh->faces().rows();
  const Eigen::Index facet =
      std::min<Eigen::Index>(faces - 1, static_cast<Eigen::Index>(unit(rng) * faces));
  const Vec3 facet_normal =
      sphere.pose.orientation * sphere.mesh->face_normals().row(facet).transpose();
  const double yaw = 2.0 * std::numbers::pi * unit(rng);
  sphere.pose.orientation = Eigen::AngleAxisd(yaw, Vec3::UnitZ()) *
                            Eigen::Quaterniond::FromTwoVectors(facet_normal, -Vec3::UnitZ()) *
                            sphere.pose.orientation;
  sphere.pose.position = support_center + off_axis_shift(scale, support_half_width, rng);
  // Lowest vertex at the margin over the support's top.
  sphere.pose.position.z() = 0.0;
  sphere.pose.position.z() =
      support_top + margin - posed_vertices(*sphere.mesh, sphere.pose).col(2).minCoeff();
  return sphere;
}

// options.stacks stacks of cubes and upright cylinders at rest on spec's floor, a share of them
// topped with a sphere. Generators of their own keep the tossed objects' draws as MOVi's, and
// stacks without spheres as they were before spheres existed; `placed` receives their bounding
// spheres so the tossed objects spawn clear of them.
void add_stacks(const MoviOptions& options, bool movi_a, std::uint64_t seed, SceneSpec& spec,
                BoundingSpheres& placed) {
  std::mt19937_64 rng(seed ^ 0x5374'6163'6b73'0001ULL);
  std::mt19937_64 sphere_rng(seed ^ 0x5370'6865'7265'0001ULL);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Source shapes[] = {{"cube"}, {"cylinder"}};  // both flat on top and bottom when upright
  const double margin = spec.collision_margin;
  for (int s = 0; s < options.stacks; ++s) {
    // Build the stack around the vertical axis through the origin, then move it to a free spot.
    // With the default 1–3 levels this is the draw the first stacks data was made with.
    const int span = options.max_stack_levels - options.min_stack_levels;
    const int levels =
        options.min_stack_levels + std::min(span, static_cast<int>(unit(rng) * (span + 1)));
    std::vector<BodySpec> stack;
    std::vector<double> half_widths;  // cube and cylinder alike: half-width = half-height = scale
    double top = spec.floor->height;
    Vec3 below_center = Vec3::Zero();
    for (int level = 0; level < levels; ++level) {
      const Source& shape = shapes[unit(rng) < 0.5 ? 0 : 1];
      const double scale = draw_scale(movi_a, false, rng);
      const Material& material = draw_material(false, rng);
      BodySpec body = make_object(shape, options.mesh_import, material, scale);
      const double yaw = 2.0 * std::numbers::pi * unit(rng);
      body.pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
      const Vec3 shift = level > 0 ? off_axis_shift(scale, half_widths.back(), rng) : Vec3::Zero();
      body.pose.position = below_center + shift;
      body.pose.position.z() = top + margin + scale;
      top = body.pose.position.z() + scale;
      below_center = body.pose.position;
      half_widths.push_back(scale);
      stack.push_back(std::move(body));
    }
    if (unit(sphere_rng) < options.sphere_topped_stacks) {
      stack.push_back(sphere_on_top(below_center, half_widths.back(), top, options, movi_a, margin,
                                    sphere_rng));
    }
    place_clear(stack, rng, spec, placed);
  }
}

// Inner half-width of the bin a pile is settled in first: two of the largest MOVi-A cubes side by
// side.
constexpr double kPileBinHalfWidth = 2.9;

// Four still walls around the vertical axis through the origin, an inner half-width of
// kPileBinHalfWidth, `height` tall and more, so nothing bounces out of the bin.
std::vector<BodySpec> pile_bin(double height) {
  std::vector<BodySpec> walls;
  for (int side = 0; side < 4; ++side) {
    const bool along_x = side < 2;
    const double sign = side % 2 == 0 ? 1.0 : -1.0;
    const double long_half = kPileBinHalfWidth + 0.5, tall_half = 0.5 * height + 1.0;
    const Vec3 half = along_x ? Vec3(0.25, long_half, tall_half) : Vec3(long_half, 0.25, tall_half);
    BodySpec wall = make_body(make_box(half), 1.0, 0.5, 0.3);
    wall.kinematic = true;
    wall.properties.mass = 0.0;
    const double offset = sign * (kPileBinHalfWidth + 0.25);
    wall.pose.position = along_x ? Vec3(offset, 0.0, tall_half) : Vec3(0.0, offset, tall_half);
    walls.push_back(std::move(wall));
  }
  return walls;
}

// options.piles piles of the preset's objects, dropped in a column and settled by Bullet, still
// on spec's floor. Their own generator keeps the tossed objects' draws as MOVi's; `placed`
// receives their bounding spheres so later bodies spawn clear of them.
void add_piles(const MoviOptions& options, bool movi_a, const std::vector<Source>& sources,
               std::uint64_t seed, SceneSpec& spec, BoundingSpheres& placed) {
  std::mt19937_64 rng(seed ^ 0x5069'6c65'7300'0001ULL);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  const int source_count = static_cast<int>(sources.size());
  for (int p = 0; p < options.piles; ++p) {
    const int span = options.max_pile_objects - options.min_pile_objects;
    const int count =
        options.min_pile_objects + std::min(span, static_cast<int>(unit(rng) * (span + 1)));
    // A column around the vertical axis through the origin, each body clear above the last, in
    // a scene of its own with the same floor and physics.
    SceneSpec drop = spec;
    drop.bodies.clear();
    double height = spec.floor->height;
    for (int i = 0; i < count; ++i) {
      const Source& source = sources[static_cast<int>(unit(rng) * source_count) % source_count];
      const double scale = draw_scale(movi_a, false, rng);
      const Material& material = draw_material(false, rng);
      BodySpec body = make_object(source, options.mesh_import, material, scale);
      const double radius = bounding_radius(body);
      body.pose.orientation =
          Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
      body.pose.position =
          Vec3(0.6 * unit(rng) - 0.3, 0.6 * unit(rng) - 0.3, height + radius + 0.05);
      height += 2.0 * radius + 0.05;
      drop.bodies.push_back(std::move(body));
    }
    // Settled in two runs of Bullet: first inside a square bin (four still walls), where the
    // column falls into a heap instead of scattering, then without the bin, where the heap slumps
    // to where it stands; each run starts still from the last one's poses.
    const int settle_frames = static_cast<int>(std::lround(3.0 / drop.frame_step()));
    auto settle = [&](const std::vector<BodySpec>& walls) {
      SceneSpec run = drop;
      run.bodies.insert(run.bodies.end(), walls.begin(), walls.end());
      BulletSimulation simulation(run);
      for (int f = 0; f < settle_frames; ++f) simulation.step_frame();
      for (size_t i = 0; i < drop.bodies.size(); ++i) {
        drop.bodies[i].pose = simulation.pose(static_cast<int>(i));
        drop.bodies[i].linear_velocity = drop.bodies[i].angular_velocity = Vec3::Zero();
      }
    };
    settle(pile_bin(height));
    settle({});
    place_clear(drop.bodies, rng, spec, placed);
  }
}

}  // namespace

const std::vector<std::string>& movi_presets() {
  static const std::vector<std::string> presets = {"movi-a", "movi-b", "movi-c", "pushing"};
  return presets;
}

int frames_or_default(const MoviOptions& options, int preset_frames) {
  if (options.frames != 0 && options.frames < 2) {
    throw ConfigError(fmt::format("frames = {} (needs >= 2)", options.frames));
  }
  return options.frames ? options.frames : preset_frames;
}

SceneSpec sample_scene(const MoviOptions& options, std::uint64_t seed) {
  if (options.preset == "pushing") {
    if (options.stacks != 0) throw ConfigError("stacks need preset movi-a or movi-b, not pushing");
    if (options.piles != 0) throw ConfigError("piles need preset movi-a or movi-b, not pushing");
    return sample_pushing_scene(options, seed);
  }
  return sample_movi_scene(options, seed);
}

SceneSpec sample_movi_scene(const MoviOptions& options, std::uint64_t seed) {
  const bool movi_a = options.preset == "movi-a", movi_c = options.preset == "movi-c";
  if (!movi_a && !movi_c && options.preset != "movi-b") {
    throw ConfigError(fmt::format("unknown scene preset '{}'; available: {}", options.preset,
                                  fmt::join(movi_presets(), ", ")));
  }
  // Tossed objects: at least one, unless stacks or piles stand in the scene.
  const int fewest = options.stacks > 0 || options.piles > 0 ? 0 : 1;
  if (options.min_objects < fewest || options.max_objects < options.min_objects) {
    throw ConfigError(fmt::format("objects range {}..{} is empty or below {}", options.min_objects,
                                  options.max_objects, fewest));
  }
  // A count of things per scene and the range of their sizes.
  auto check_counts = [](const char* things, int count, const char* sizes, int low, int high,
                         int most) {
    if (count < 0) throw ConfigError(fmt::format("{} = {} (must be >= 0)", things, count));
    if (low < 1 || high < low || high > most) {
      throw ConfigError(
          fmt::format("{} {}..{}: need 1 <= min <= max <= {}", sizes, low, high, most));
    }
  };
  check_counts("stacks", options.stacks, "stack levels", options.min_stack_levels,
               options.max_stack_levels, kMaxStackLevels);
  check_counts("piles", options.piles, "pile objects", options.min_pile_objects,
               options.max_pile_objects, kMaxPileObjects);
  if (!(options.sphere_topped_stacks >= 0.0 && options.sphere_topped_stacks <= 1.0)) {
    throw ConfigError(fmt::format("sphere_topped_stacks = {} (a share: needs 0 to 1)",
                                  options.sphere_topped_stacks));
  }
  if (options.sphere_topped_stacks > 0.0 && options.stacks == 0) {
    throw ConfigError(fmt::format(
        "sphere_topped_stacks = {} tops stacks with spheres, but stacks = 0: ask for stacks too",
        options.sphere_topped_stacks));
  }
  if (options.piles > 0 && movi_c) {
    throw ConfigError("piles need preset movi-a or movi-b, not movi-c");
  }
  if (options.stacks > 0 && movi_c) {
    throw ConfigError("stacks need cubes and cylinders: preset movi-a or movi-b, not movi-c");
  }
  if (movi_c && options.assets.empty()) {
    throw ConfigError("preset movi-c takes its objects from a folder of mesh files: give one");
  }
  if (movi_a && !options.assets.empty()) {
    throw ConfigError(
        "preset movi-a has only cubes, cylinders and spheres: assets need movi-b or "
        "movi-c");
  }
  // MOVi-A: cube, cylinder, sphere. MOVi-B: all eight MOVi shapes and the asset files.
  // MOVi-C: the asset files only.
  std::vector<Source> sources;
  if (!movi_c) {
    const std::vector<std::string>& shapes = movi_shape_names();
    for (size_t i = 0; i < (movi_a ? 3 : shapes.size()); ++i) sources.push_back({shapes[i]});
  }
  if (!options.assets.empty()) {
    for (const auto& file : asset_files(options.assets))
      sources.push_back({file.string(), true, movi_c ? 1.0 : 2.0});
  }
  for (const Source& source : sources)
    unit_geometry(source, options.mesh_import);  // checked up front
  SceneSpec spec;
  spec.seed = seed;
  spec.frames = frames_or_default(options, 96);
  spec.floor = Floor{0.0, {0.0, 0.3, 0.5}};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  const int source_count = static_cast<int>(sources.size());
  const int count = options.min_objects +
                    static_cast<int>(unit(rng) * (options.max_objects - options.min_objects + 1));
  BoundingSpheres spheres;  // placed bodies' bounding spheres
  if (options.stacks > 0) add_stacks(options, movi_a, seed, spec, spheres);
  if (options.piles > 0) add_piles(options, movi_a, sources, seed, spec, spheres);
  for (int i = 0; i < std::min(count, options.max_objects); ++i) {
    const Source& source = sources[static_cast<int>(unit(rng) * source_count) % source_count];
    const double scale = draw_scale(movi_a, movi_c, rng);
    const Material& material = draw_material(movi_c, rng);
    BodySpec body = make_object(source, options.mesh_import, material, scale);
    const double radius = bounding_radius(body);
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
      placed = placed && clear_of(spheres, body.pose.position, radius);
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
