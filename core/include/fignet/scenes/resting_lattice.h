// A procedural scene without physics: MOVi shapes in random orientations on a square lattice just
// above the floor, each drifting with a small random velocity. Neighbours and the floor come within
// the collision radius, so the graph has every edge type. Used by the CLI's graph statistics,
// tests and benchmarks; the object density is the same for any object count.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fignet/graph/scene.h"

namespace fignet {

struct RestingLatticeOptions {
  int objects = 6;
  std::uint64_t seed = 0;
  int history = 2;                                                   // velocities (h + 1 poses)
  std::vector<std::string> shapes = {"cube", "cylinder", "sphere"};  // MOVi-A
  std::vector<double> scales = {0.35, 0.7};                          // shape scale factors
  double gap = 0.05;   // clearance between neighbours' bounding spheres, metres
  double speed = 0.5;  // magnitude of the random drift, m/s
  double time_step = 1.0 / 48.0;
};

// Owns the meshes its scene points to.
struct RestingLattice {
  std::vector<std::unique_ptr<TriangleMesh>> meshes;
  Scene scene;
};

// Throws ConfigError for an unknown shape or a non-positive count or scale.
RestingLattice make_resting_lattice(const RestingLatticeOptions& options);

}  // namespace fignet
