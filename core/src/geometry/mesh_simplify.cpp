// simplify_mesh(): meshoptimizer's edge-collapse simplifier under a vertex budget.
#include <meshoptimizer.h>

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <vector>

#include "fignet/error.h"
#include "fignet/geometry/mesh_repair.h"

namespace fignet {

namespace {

// The mesh of the faces `indices` names (three per face).
TriangleMesh compact(const TriangleMesh& mesh, const std::vector<unsigned>& indices) {
  std::vector<std::array<int, 3>> faces(indices.size() / 3);
  for (size_t i = 0; i < indices.size(); ++i) faces[i / 3][i % 3] = static_cast<int>(indices[i]);
  return mesh_of_used_vertices(mesh.name(), mesh.vertices(), faces);
}

// The result with its closedness recorded.
SimplifiedMesh finished(SimplifiedMesh result) {
  result.closed = result.mesh.is_closed();
  return result;
}

}  // namespace

SimplifiedMesh simplify_mesh(const TriangleMesh& mesh, const SimplifyOptions& options) {
  if (options.max_vertices < 4) {
    throw ConfigError(
        fmt::format("mesh '{}': vertex budget {} (needs >= 4)", mesh.name(), options.max_vertices));
  }
  if (!(options.tolerance > 0.0 && options.tolerance <= 1.0)) {
    throw ConfigError(fmt::format("mesh '{}': simplification tolerance {} (must be in (0, 1])",
                                  mesh.name(), options.tolerance));
  }
  const bool closed = mesh.is_closed();
  SimplifiedMesh result{mesh, 0.0, false, closed};
  if (mesh.num_vertices() <= options.max_vertices) return result;
  // meshoptimizer works in float, relative to the mesh's extent: a mesh whose extent float cannot
  // hold stays as it is, and positions are taken about the box centre so a mesh far from the
  // origin keeps its precision.
  const Vec3 lower = mesh.vertices().colwise().minCoeff(),
             upper = mesh.vertices().colwise().maxCoeff();
  if (!((upper - lower).maxCoeff() < 1e30)) return result;
  const Vec3 centre = 0.5 * (upper + lower);
  std::vector<float> positions(static_cast<size_t>(3 * mesh.num_vertices()));
  for (int v = 0; v < mesh.num_vertices(); ++v)
    for (int k = 0; k < 3; ++k)
      positions[static_cast<size_t>(3 * v + k)] =
          static_cast<float>(mesh.vertices()(v, k) - centre[k]);
  std::vector<unsigned> indices(static_cast<size_t>(3 * mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      indices[static_cast<size_t>(3 * f + k)] = static_cast<unsigned>(mesh.faces()(f, k));
  const double scale = meshopt_simplifyScale(positions.data(), mesh.num_vertices(), 12);

  // The budget is in vertices, meshoptimizer's target in faces (a closed mesh has about twice
  // as many faces as vertices). Edge collapse may leave a closed mesh with a non-manifold edge at
  // one target and not at a nearby one, and a closed mesh must stay closed: targets are swept
  // downward from the budget in 5 % steps, and the first closed attempt within the budget wins.
  // When the tolerance stops every attempt above the budget, the closed one with the fewest
  // vertices does.
  std::vector<unsigned> simplified(indices.size());
  // One attempt at `target_faces`; true when it gave a usable mesh within the budget.
  const auto attempt = [&](double target_faces, size_t& count) {
    target_faces = std::min(target_faces, static_cast<double>(mesh.num_faces()));
    float error = 0.0f;
    count = meshopt_simplify(simplified.data(), indices.data(), indices.size(), positions.data(),
                             static_cast<size_t>(mesh.num_vertices()), 12,
                             3 * static_cast<size_t>(target_faces),
                             static_cast<float>(options.tolerance), 0, &error);
    if (count == 0 || count == indices.size()) return false;
    TriangleMesh candidate = compact(
        mesh,
        std::vector<unsigned>(simplified.begin(), simplified.begin() + static_cast<long>(count)));
    if (closed && !candidate.is_closed()) return false;
    const bool within = candidate.num_vertices() <= options.max_vertices;
    if (within || !result.changed || candidate.num_vertices() < result.mesh.num_vertices()) {
      result.mesh = std::move(candidate);
      result.error = static_cast<double>(error) * scale;
      result.changed = true;
    }
    return within;
  };
  // Downward from the budget until an attempt fits, or the tolerance holds the result where it
  // was (a smaller target gives the same mesh)...
  size_t count = 0, previous = 0;
  for (int step = 0; step < 40; ++step) {
    if (attempt(2.0 * options.max_vertices * std::pow(0.95, step), count)) {
      return finished(std::move(result));
    }
    if (count == previous) break;
    previous = count;
  }
  // ...then, when no attempt there stayed closed, upward until one does.
  for (int step = 1; step <= 30 && !result.changed; ++step) {
    attempt(2.0 * options.max_vertices * std::pow(1.1, step), count);
    if (count == indices.size()) break;
  }
  return finished(std::move(result));
}

}  // namespace fignet
