// Every tunable of a FIGNet model — graph, network size, training noise, normalisation, and the
// physical setting it was trained in — in one struct, saved in and checked against model files.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fignet/geometry/types.h"
#include "fignet/graph/config.h"

namespace fignet {

// How training noise corrupts the input positions (the velocities the network sees).
enum class NoiseKind {
  kVertex,  // an independent random walk per vertex (GNS); Kabsch removes it in rollouts
  kRigid,   // a random walk of each body's pose, vertices and centre together: the whole-body
            // drift that rollouts accumulate
};

// The range of one property over the training data's bodies: metadata, no parameter depends on
// it. Empty (lowest > highest): unknown, as in model files from before it was recorded.
struct DataRange {
  double lowest = 1.0, highest = 0.0;

  bool known() const { return lowest <= highest; }
  // Widens the range to hold `value`.
  void add(double value);
  // Whether `value` lies within the range, up to float32 rounding of the data; true when unknown.
  bool holds(double value) const;
  // For messages: "0.3" for a range of one value, "0.4-0.8", or "unknown".
  std::string text() const;
};

struct ModelConfig {
  std::string preset = "paper";
  GraphConfig graph;
  int latent_size = 128;           // L: hidden and output width of every MLP (seed C.2)
  int message_passing_steps = 10;  // M, unshared weights (seed C.1.2)
  // Width of the two hidden layers of every MLP; 0: latent_size (seed C.2). Latents stay L wide.
  int hidden_size = 0;
  // Of the object-node MLPs alone (encoder and processor); 0: as the others. They run on one row
  // per body, a few per scene, so a wider one costs next to nothing beside the mesh's MLPs.
  int object_hidden_size = 0;
  double noise_std = 3e-4;  // random-walk noise at the last input position, metres
  NoiseKind noise = NoiseKind::kVertex;
  // Share of the last input position's noise that the training target undoes: 0 the velocity
  // noise only (GNS, the paper: a displaced body keeps its offset), 1 the position too (the model
  // learns to pull a displaced or penetrating body back where the truth has it).
  double noise_correction = 0.0;
  // Turn each training sample about the vertical (z) axis by a uniform random angle: the physics
  // has no preferred horizontal direction. Measured on two seeds it helped one (-4 % test error)
  // and hurt the other (+10 %), and did not remove the sideways push models give a body at rest
  // (training study).
  bool random_yaw = false;
  std::int64_t normalizer_max_accumulations = 1'000'000;  // statistics freeze afterwards
  double time_step = 1.0 / 48.0;   // seconds between the frames the model was trained on
  Vec3 gravity = Vec3(0, 0, -10);  // the training data's gravity
  // The most vertices of one object's mesh in the training data (0: unknown, a model file from
  // before it was recorded): the resolution the model knows, and FIGNetDynamicsWorld's default
  // node budget for finer meshes.
  int mesh_vertices = 0;
  // The lightest and heaviest dynamic body of the training data, kg (both 0: unknown, a model
  // file from before they were recorded). Predictors bring a scene's masses within them by one
  // common factor (PredictionOptions::fit_masses).
  double min_mass = 0.0, max_mass = 0.0;
  // The materials of the training data: friction and restitution of its bodies (dynamic and
  // kinematic) and of its floor. MOVi-A's bodies are two materials on one floor, so a scene of
  // other materials asks the model to guess; FIGNetDynamicsWorld counts such bodies
  // (FIGNetStepStats::unfamiliar_bodies, unfamiliar_floor).
  DataRange friction, restitution, floor_friction, floor_restitution;
  // The four material ranges by name ("friction", ..., "floor_restitution"): one list for model
  // files, validation and bindings.
  std::array<std::pair<const char*, const DataRange*>, 4> material_ranges() const {
    return {{{"friction", &friction},
             {"restitution", &restitution},
             {"floor_friction", &floor_friction},
             {"floor_restitution", &floor_restitution}}};
  }
  std::array<std::pair<const char*, DataRange*>, 4> material_ranges() {
    return {{{"friction", &friction},
             {"restitution", &restitution},
             {"floor_friction", &floor_friction},
             {"floor_restitution", &floor_restitution}}};
  }
  std::uint64_t seed = 0;  // parameter initialisation

  // The hidden width of the MLPs, and of the object-node MLPs (0 fields resolved).
  int mlp_hidden() const { return hidden_size > 0 ? hidden_size : latent_size; }
  int object_mlp_hidden() const {
    return object_hidden_size > 0 ? object_hidden_size : mlp_hidden();
  }

  // "paper": L = 128, M = 10, d_c = 0.1 m (seed C.2). "small": L = 64, M = 5, about 10x fewer
  // FLOPs, for quick training and fast inference. Throws ConfigError for another name.
  static ModelConfig preset_named(std::string_view name);
  static const std::vector<std::string>& preset_names();

  // Throws ConfigError naming the first invalid field.
  void validate() const;
};

}  // namespace fignet
