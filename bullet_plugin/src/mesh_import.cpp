#include "fignet/bullet/mesh_import.h"

#include <fmt/format.h>

#include <iostream>

#include "fignet/bullet/convex_decomposition.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "mesh_assembler.h"

namespace fignet::bullet {

const char* mesh_inertia_name(MeshInertia inertia) {
  switch (inertia) {
    case MeshInertia::kAuto:
      return "auto";
    case MeshInertia::kVolume:
      return "volume";
    case MeshInertia::kConvexHull:
      return "convex";
    case MeshInertia::kShell:
      return "shell";
  }
  return "?";
}

MeshInertia parse_mesh_inertia(const std::string& name) {
  for (MeshInertia mode :
       {MeshInertia::kAuto, MeshInertia::kVolume, MeshInertia::kConvexHull, MeshInertia::kShell}) {
    if (name == mesh_inertia_name(mode)) return mode;
  }
  throw ConfigError(fmt::format("mesh inertia '{}': expected auto, volume, convex or shell", name));
}

std::string ImportedMesh::actions() const {
  std::vector<std::string> done;
  if (!repair.empty()) {
    done.push_back(
        fmt::format("FIGNet sees its {} ({} vertices)", repair, vertices_before_simplification));
  }
  if (hull_collision)
    done.push_back("Bullet collides its convex hull (HACD's pieces cover too little of it)");
  if (simplified()) {
    done.push_back(fmt::format("simplified for the graph from {} to {} vertices (deviation {:.3g})",
                               vertices_before_simplification, surface.num_vertices(),
                               simplification_error));
  }
  return fmt::format("{}", fmt::join(done, "; "));
}

namespace {

TriangleMesh hull_of(const TriangleMesh& mesh) {
  const MeshAssembler hull = convex_hull_triangles(mesh.vertices());
  if (hull.empty()) {
    throw MeshError(fmt::format(
        "mesh '{}': flat (all its vertices lie in a plane), so it has no volume and no convex "
        "hull; use shell inertia with a mass",
        mesh.name()));
  }
  return hull.finish(mesh.name());
}

}  // namespace

ImportedMesh import_mesh(const TriangleMesh& mesh, const MeshImportOptions& options) {
  if (options.max_graph_vertices != 0 && options.max_graph_vertices < 4) {
    throw ConfigError(fmt::format("mesh '{}': graph vertex budget {} (0 for none, or >= 4)",
                                  mesh.name(), options.max_graph_vertices));
  }
  // Weld, drop degenerate and repeated faces, wind each shell consistently and outward.
  CleanedMesh cleaned = clean_mesh(mesh.name(), mesh.vertices(), mesh.faces());
  ImportedMesh result{cleaned.mesh, cleaned.mesh, cleaned.defects, "", 0, 0.0, {}, false};
  const bool closed = result.closed();

  // What the graph sees: the mesh when closed, otherwise a closed surface around it.
  if (!closed && options.repair) {
    if (mesh_wrapping_available()) {
      result.surface = wrap_mesh(cleaned.mesh, options.wrap);
      result.repair = "alpha wrap";
    } else {
      result.surface = hull_of(cleaned.mesh);
      result.repair = "convex hull";
    }
  }
  result.vertices_before_simplification = result.surface.num_vertices();

  // The node budget: simplify for the graph, keeping the surface closed.
  if (options.max_graph_vertices > 0 &&
      result.surface.num_vertices() > options.max_graph_vertices) {
    const SimplifiedMesh simplified =
        simplify_mesh(result.surface, {options.max_graph_vertices, options.simplify_tolerance});
    if (simplified.changed && (simplified.closed || !result.surface.is_closed())) {
      result.surface = simplified.mesh;
      result.simplification_error = simplified.error;
    }
  }

  // Bullet's collision shape: convex pieces (HACD) of the closed surface, whose deviation from
  // the full mesh is far below HACD's own concavity tolerance; a convex mesh keeps the exact hull
  // of all its vertices.
  if (result.surface.is_closed()) {
    result.convex_parts = collision_parts(result.surface, &result.hull_collision);
  }
  if (result.convex_parts.empty() && (result.simplified() || result.hull_collision)) {
    result.convex_parts.push_back(result.cleaned.vertices());
  }

  const std::string actions = result.actions();
  if (!result.defects.clean() || !actions.empty()) {
    const std::string line =
        fmt::format("mesh '{}' ({} vertices): {}{}{}", mesh.name(), mesh.num_vertices(),
                    result.defects.summary(), actions.empty() ? "" : "; ", actions);
    if (options.warn) {
      options.warn(line);
    } else {
      std::cerr << "fignet: warning: " << line << '\n';
    }
  }
  return result;
}

UnitInertia mesh_inertia(const ImportedMesh& mesh, MeshInertia inertia) {
  const bool closed = mesh.closed();
  if (inertia == MeshInertia::kVolume && !closed) {
    throw MeshError(fmt::format(
        "mesh '{}': not closed ({}), so it has no volume; choose convex or shell inertia",
        mesh.cleaned.name(), mesh.defects.summary()));
  }
  if (inertia == MeshInertia::kShell) {
    const ShellProperties shell = compute_shell_properties(mesh.cleaned);
    return {shell.area, shell.center_of_mass, shell.inertia, 2};
  }
  const bool hull =
      inertia == MeshInertia::kConvexHull || (inertia == MeshInertia::kAuto && !closed);
  const MassProperties volume =
      compute_mass_properties(hull ? hull_of(mesh.cleaned) : mesh.cleaned);
  return {volume.volume, volume.center_of_mass, volume.inertia, 3};
}

}  // namespace fignet::bullet
