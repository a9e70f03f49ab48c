// Random multi-object scenes for graph tests: shapes in random poses inside a small box, so they
// overlap, touch and come within the collision radius of each other and of the floor.
#pragma once

#include <memory>
#include <random>
#include <vector>

#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"
#include "fignet/graph/scene.h"

namespace fignet::testing {

struct RandomScene {
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;
  Scene scene;
};

inline Eigen::Quaterniond random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

// `objects` MOVi-A-like shapes (scaled 0.2–0.4) in a box of half-width `spread`; every third
// object is kinematic and moves by a small displacement at the next step.
inline RandomScene make_random_scene(unsigned seed, int objects, double spread, int history = 2) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RandomScene result;
  const char* shapes[] = {"cube", "sphere", "cylinder", "cone"};
  for (int i = 0; i < objects; ++i) {
    const TriangleMesh unit = centered_on_center_of_mass(make_movi_shape(shapes[i % 4]));
    const double scale = 0.3 + 0.1 * u(rng);
    auto mesh =
        std::make_shared<const TriangleMesh>(unit.name(), unit.vertices() * scale, unit.faces());
    result.meshes.push_back(mesh);
    SceneObject object;
    object.mesh = mesh.get();
    std::vector<Pose> poses(history + 1);
    const Vec3 velocity = 0.05 * Vec3(u(rng), u(rng), u(rng));
    const Vec3 position = spread * Vec3(u(rng), u(rng), 0.5 * (u(rng) + 1.0));
    const Eigen::Quaterniond orientation = random_rotation(rng);
    for (int k = 0; k <= history; ++k) {
      poses[k].position = position + (k - history) * velocity;
      poses[k].orientation =
          Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * (k - history), Vec3::UnitZ())) * orientation;
    }
    object.kinematic = i % 3 == 2;
    Pose next = poses.back();
    next.position += velocity;
    set_pose_history(object, poses, object.kinematic ? std::optional(next) : std::nullopt);
    object.properties = {object.kinematic ? 0.0 : 1.0 + i, 0.5, 0.3};
    result.scene.objects.push_back(std::move(object));
  }
  result.scene.floor = Floor{};
  return result;
}

}  // namespace fignet::testing
