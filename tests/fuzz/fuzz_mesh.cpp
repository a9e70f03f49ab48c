// libFuzzer harness: arbitrary bytes as a triangle mesh (vertex count, vertices as floats, faces
// as indices). Construction may fail only with a MeshError; a mesh that is accepted must go
// through mass properties (when closed) and the face-pair search against a cube without a crash.
// The same bytes as a file's triangles go through clean_mesh, shell properties and simplify_mesh.
#include <cstdint>
#include <cstring>
#include <vector>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/mesh_repair.h"
#include "fignet/geometry/shapes.h"
#include "fignet/graph/graph_builder.h"

namespace {

template <class T>
bool take(const std::uint8_t*& data, std::size_t& size, T& out) {
  if (size < sizeof(T)) return false;
  std::memcpy(&out, data, sizeof(T));
  data += sizeof(T), size -= sizeof(T);
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint8_t vertices = 0;
  if (!take(data, size, vertices) || vertices == 0) return 0;
  fignet::Points points(vertices, 3);
  for (int v = 0; v < vertices; ++v) {
    for (int c = 0; c < 3; ++c) {
      float x = 0;
      if (!take(data, size, x)) return 0;
      points(v, c) = x;
    }
  }
  std::vector<std::array<int, 3>> faces;
  std::uint8_t corner[3];
  while (take(data, size, corner)) faces.push_back({corner[0], corner[1], corner[2]});
  fignet::Triangles triangles(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int c = 0; c < 3; ++c) triangles(static_cast<Eigen::Index>(f), c) = faces[f][c];
  }
  try {
    const fignet::CleanedMesh cleaned = fignet::clean_mesh("fuzz", points, triangles);
    (void)cleaned.defects.summary();
    (void)fignet::compute_shell_properties(cleaned.mesh);
    if (cleaned.mesh.is_closed()) (void)fignet::compute_mass_properties(cleaned.mesh);
    (void)fignet::simplify_mesh(cleaned.mesh, {4, 0.05});
  } catch (const fignet::Error&) {
  }
  try {
    fignet::MeshOptions options;
    options.degenerate_faces = fignet::DegenerateFaces::kDrop;
    const fignet::TriangleMesh mesh("fuzz", points, triangles, options);
    if (mesh.is_closed()) (void)fignet::compute_mass_properties(mesh);
    static const fignet::TriangleMesh cube = fignet::make_box(fignet::Vec3::Constant(0.5), 1);
    fignet::Scene scene;
    for (const fignet::TriangleMesh* m : {&mesh, &cube}) {
      scene.objects.emplace_back();
      scene.objects.back().mesh = m;
      std::vector<fignet::Pose> poses(3);
      fignet::set_pose_history(scene.objects.back(), poses, std::nullopt);
    }
    fignet::GraphBuilder builder(fignet::GraphConfig{});
    fignet::Graph graph;
    builder.build(scene, graph);
  } catch (const fignet::Error&) {
  }
  return 0;
}
