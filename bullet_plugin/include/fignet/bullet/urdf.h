// Rigid bodies from URDF files (urdfdom), for scenes of free objects such as Kubric's assets:
// links joined by fixed joints merge into one body, floating joints separate free bodies, and
// every other joint type is an error, because FIGNet simulates free rigid bodies.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "fignet/bullet/scene_spec.h"

namespace fignet::bullet {

struct UrdfOptions {
  Pose base_pose;  // where the root link's frame is placed in the world
  // Used where the file is silent: density for bodies none of whose links has <inertial>, and
  // friction and restitution for links without PyBullet's <contact> element.
  double default_density = 1000.0;
  double default_friction = 0.5, default_restitution = 0.0;
  // package://NAME/… mesh URIs resolve to packages[NAME]/…; a NAME not listed resolves to the
  // nearest folder called NAME above the URDF file.
  std::map<std::string, std::filesystem::path> packages;
  // How <mesh> files become collision pieces: repair of open meshes, the graph's node budget
  // (mass comes from <inertial>, or the repaired surfaces at default_density).
  MeshImportOptions mesh;
};

struct UrdfBody {
  std::string name;                // the link at the root of the merged group
  std::vector<std::string> links;  // every link merged into this body, root first
  BodySpec body;
};

// One body per group of links joined by fixed joints, root group first. Collision geometry
// (box, cylinder, sphere, mesh files through assimp, several per link) becomes the body's mesh
// and convex parts (non-convex meshes through HACD, as load_body does); <inertial> data of the
// merged links is combined by the parallel-axis theorem (a total mass of 0 gives a static,
// kinematic body, as in PyBullet); <contact><lateral_friction/><restitution/></contact> of the
// group's root link sets the material. Throws FileError (unreadable file, invalid URDF with
// urdfdom's reason, missing mesh file) or ConfigError (unsupported joint, a body without
// collision geometry), each naming the file and the link or joint.
std::vector<UrdfBody> load_urdf(const std::filesystem::path& path, const UrdfOptions& options = {});

}  // namespace fignet::bullet
