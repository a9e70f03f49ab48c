// Scenes for the network's tests and benchmarks: MOVi-A-like resting lattices (bodies 0.7–1.4 m
// across), one per seed 1, 2, ...
#pragma once

#include <cstdint>
#include <vector>

#include "fignet/scenes/resting_lattice.h"

namespace fignet::testing {

// `objects_of(s)` objects in the s-th lattice (s from 0).
template <class Objects>
std::vector<RestingLattice> movi_a_lattices(int count, Objects&& objects_of) {
  std::vector<RestingLattice> lattices;
  for (int s = 0; s < count; ++s) {
    RestingLatticeOptions options;
    options.objects = objects_of(s);
    options.seed = static_cast<std::uint64_t>(s + 1);
    options.scales = {0.7, 1.4};
    lattices.push_back(make_resting_lattice(options));
  }
  return lattices;
}

// Their scenes, as one batch for the graph builder.
inline std::vector<Scene> scenes_of(const std::vector<RestingLattice>& lattices) {
  std::vector<Scene> scenes;
  for (const RestingLattice& l : lattices) scenes.push_back(l.scene);
  return scenes;
}

}  // namespace fignet::testing
