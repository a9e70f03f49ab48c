// Kubric MOVi scene presets (facts §1) as SceneSpecs: objects tossed toward the centre onto a
// floor, Bullet at 240 Hz, one frame every 5 steps.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fignet/bullet/scene_spec.h"

namespace fignet::bullet {

inline constexpr int kMaxStackLevels = 10;
inline constexpr int kMaxPileObjects = 20;

struct MoviOptions {
  std::string preset = "movi-a";  // "movi-a", "movi-b", "movi-c" or "pushing"
  int min_objects = 3, max_objects = 10;
  int frames = 0;  // 0: the preset's own (movi-a 96, pushing 42)
  // Stacks of cubes and upright cylinders standing still on the floor when a movi-a or movi-b
  // scene starts, this many per scene, placed before the tossed objects (which spawn clear of them
  // and may knock them over). MOVi throws every body, so its data holds few bodies resting on one
  // another and no stack; 0 keeps MOVi's scenes, bit for bit.
  int stacks = 0;
  // Levels per stack, uniform in this range (at most kMaxStackLevels). 1–3 is what the stacks
  // data of issue 14 used; taller stacks put more of the data's rest on other bodies.
  int min_stack_levels = 1, max_stack_levels = 3;
  // Share (0–1) of the stacks topped with a MOVi sphere resting still on one of its facets. Round
  // bodies roll off piles and MOVi throws every body, so without these no sphere in the data rests
  // on another body (the stress suite's "MOVi sphere on a MOVi cube"). Drawn from a generator of
  // their own; 0 keeps the stacks bit for bit.
  double sphere_topped_stacks = 0.0;
  // Settled piles when the scene starts, this many per scene: min_pile_objects–max_pile_objects
  // of the preset's objects dropped in a narrow column and settled by Bullet before the first
  // frame, so bodies lean on one another and on the floor at odd angles, which neither MOVi nor
  // the stacks show. They start still, but round bodies may roll off (Bullet has no rolling
  // friction here). Placed after the stacks and before the tossed objects, from their own
  // generator; 0 keeps the scenes without piles, bit for bit.
  int piles = 0;
  int min_pile_objects = 3, max_pile_objects = 6;
  // A folder of mesh files: extra objects for movi-b, the only objects of movi-c.
  std::filesystem::path assets;
  // How asset meshes become bodies: repair, node budget, inertia mode (see mesh_import.h).
  MeshImportOptions mesh_import;
};

// The scene of `seed`: 3–10 objects from {cube, cylinder, sphere}, scale 0.7 or 1.4, metal
// (friction 0.4, restitution 0.3, density 2.7) or rubber (0.8, 0.7, 1.1), random orientation,
// positions uniform in (−5,−5,1)–(5,5,5) resampled (≤ 100 tries) until the object's bounding
// sphere overlaps no earlier one and its lowest point is above the floor, and a horizontal
// velocity uniform in (−4,−4,0)–(4,4,0) minus the spawn point's (x, y, 0): tossed toward the
// centre. Floor friction 0.3, restitution 0.5; gravity (0, 0, −10). "movi-b" draws from all eight
// MOVi shapes (non-convex ones as compounds of their exact convex parts) with scale uniform in
// 0.7–1.4, plus the mesh files of options.assets scaled to a 2 m largest side like the KuBasic
// shapes. "movi-c" draws only from options.assets: largest side 1 m times U(0.75, 3.0) (Kubric's
// MOVi-C worker), friction 0.5, restitution 0.5, density 1.0 (facts §1). Mesh files may be open
// or messy (options.mesh_import says how they are repaired, simplified and weighed); non-convex
// ones collide as HACD decompositions. options.stacks adds stacks at rest (a variant, not MOVi):
// the stacks come first, from their own generator, each at a uniform spot in (−4,−4)–(4,4) clear
// of the stacks before it (≤ 100 tries, else left out), min_stack_levels–max_stack_levels levels
// high (uniform), each level a cube or an upright cylinder
// of the preset's scales and materials, turned by a uniform angle about the vertical, shifted by
// at most a tenth of the smaller of its and its support's half-widths, and resting on its support
// at the collision margin; a share options.sphere_topped_stacks of them (uniform draw) carry one
// more level, a sphere of the preset's scales and materials resting on a uniformly drawn facet,
// turned by a uniform angle about the vertical and shifted as the levels are. options.piles adds
// settled piles (a variant, not MOVi): each of min_pile_objects–max_pile_objects (uniform) objects
// drawn as the tossed ones are (shape, scale, material), at random orientations, one above the
// other with up to 0.3 m of horizontal jitter, dropped into a 5.8 m square bin of still walls and
// settled by Bullet for 3 s, then 3 s more without the bin (each run from the last one's poses,
// still), then moved whole to a uniform spot in (−4,−4)–(4,4) clear of the bodies before it (≤ 100
// tries, else left out), still. Throws ConfigError for a bad option, FileError or MeshError for a
// bad asset folder or file.
SceneSpec sample_movi_scene(const MoviOptions& options, std::uint64_t seed);

// The MIT-pushing stand-in (seed B.2, facts §2) of `seed`: a planar prism (rectangle, triangle,
// ellipse or hexagon, 4–8 cm across, 2 cm thick, 1000 kg/m³, friction 0.25) resting on a support
// plane (friction 0.25), and a kinematic cylindrical pusher (radius 5 mm, mass 0, its nodes
// kinematic) moving at a constant 5–15 cm/s toward a random point of the prism's side, at a random
// angle within ±30° of the side's normal. Bullet at 250 Hz, 125 steps recorded every 3 (42 frames).
SceneSpec sample_pushing_scene(const MoviOptions& options, std::uint64_t seed);

// options.frames, or the preset's own count when it is 0; throws ConfigError below 2.
int frames_or_default(const MoviOptions& options, int preset_frames);

// Dispatches on options.preset; throws ConfigError naming the valid presets.
SceneSpec sample_scene(const MoviOptions& options, std::uint64_t seed);
const std::vector<std::string>& movi_presets();

}  // namespace fignet::bullet
