// Bodies from mesh files (through assimp) dropped on a floor, in native Bullet or, with a model
// file, in FIGNet: an L-shaped OBJ block (non-convex: split into convex parts by HACD), an STL
// octahedron and an open cup (no top: FIGNet sees its alpha wrap, mass from its convex hull, and
// one warning line says so). Any file assimp reads works the same way, given on the command line
// after the model.
//
//   build/release/examples/example_mesh_file_scene                           # native Bullet
//   build/release/examples/example_mesh_file_scene models/movi-a.h5          # FIGNet
//   build/release/examples/example_mesh_file_scene - my_part.stl other.glb   # native, your files
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "fignet/bullet/rigid_bodies.h"
#include "fignet/bullet/scene_spec.h"
#include "fignet/error.h"
#include "world_choice.h"

int main(int argc, char** argv) try {
  using namespace fignet::bullet;
  const bool native = argc < 2 || std::string(argv[1]) == "-";
  WorldChoice choice(native ? nullptr : argv[1]);
  RigidBodies bodies(*choice.world);
  bodies.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0, btVector3(0, 0, 0),
             btTransform::getIdentity());

  std::vector<std::string> files(argv + std::min(argc, 2), argv + argc);
  if (files.empty()) {
    files = {FIGNET_EXAMPLE_ASSETS "/l_block.obj", FIGNET_EXAMPLE_ASSETS "/octahedron.stl",
             FIGNET_EXAMPLE_ASSETS "/open_cup.obj"};
  }
  std::vector<std::pair<std::string, const btRigidBody*>> labelled;
  for (size_t i = 0; i < files.size(); ++i) {
    // One call from a file to a body: 500 kg/m³ wood, mass from the mesh's volume (its convex
    // hull's when the mesh is open).
    BodyMaterial wood;
    wood.density = 500.0;
    wood.friction = 0.6;
    BodySpec body = load_body(files[i], wood);
    body.pose.position = fignet::Vec3(0.5 * static_cast<double>(i), 0, 0.5);
    labelled.emplace_back(std::filesystem::path(files[i]).filename().string(), bodies.add(body));
    std::printf("%s: %d vertices, %.3f kg, %zu convex part(s)\n", files[i].c_str(),
                body.mesh->num_vertices(), body.properties.mass,
                std::max<size_t>(1, body.convex_parts.size()));
  }

  choice.run_and_print(labelled);
  return 0;
} catch (const fignet::Error& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
