// Bodies from URDF files dropped on a floor, in native Bullet or, with a model file, in FIGNet:
// a dumbbell (three links welded by fixed joints: one rigid body) and a crate whose L-shaped
// block, a mesh file, rides on a floating joint (two free bodies).
//
//   build/release/examples/example_urdf_scene                      # native Bullet
//   build/release/examples/example_urdf_scene models/movi-a.h5     # FIGNet
#include <cstdio>

#include "fignet/bullet/rigid_bodies.h"
#include "fignet/bullet/urdf.h"
#include "fignet/error.h"
#include "world_choice.h"

int main(int argc, char** argv) try {
  using namespace fignet::bullet;
  WorldChoice choice(argc > 1 ? argv[1] : nullptr);
  RigidBodies bodies(*choice.world);
  bodies.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0, btVector3(0, 0, 0),
             btTransform::getIdentity());

  // Each file is placed by its root link; every merged or free body becomes one btRigidBody.
  UrdfOptions dumbbell_at;
  dumbbell_at.base_pose.position = fignet::Vec3(0.3, 0, 0.6);
  dumbbell_at.base_pose.orientation = Eigen::AngleAxisd(1.2, fignet::Vec3::UnitY());
  UrdfOptions crate_at;
  crate_at.base_pose.position = fignet::Vec3(-0.4, 0, 0.3);
  std::vector<UrdfBody> loaded = load_urdf(FIGNET_EXAMPLE_ASSETS "/dumbbell.urdf", dumbbell_at);
  for (UrdfBody& body : load_urdf(FIGNET_EXAMPLE_ASSETS "/crate.urdf", crate_at)) {
    loaded.push_back(std::move(body));
  }
  std::vector<std::pair<std::string, const btRigidBody*>> labelled;
  for (const UrdfBody& body : loaded) {
    labelled.emplace_back(body.name, bodies.add(body.body));
    std::printf("%-8s %zu link(s), %.3f kg, %zu convex part(s)\n", body.name.c_str(),
                body.links.size(), body.body.properties.mass,
                std::max<size_t>(1, body.body.convex_parts.size()));
  }

  choice.run_and_print(labelled);
  return 0;
} catch (const fignet::Error& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
