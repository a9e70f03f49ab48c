#include "fignet/bullet/mesh_file.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>

#include "fignet/error.h"
#include "isolated_call.h"

namespace fignet::bullet {

namespace fs = std::filesystem;

const std::vector<std::string>& mesh_file_extensions() {
  static const std::vector<std::string> extensions = {".obj", ".stl", ".ply", ".gltf",
                                                      ".glb", ".off", ".dae", ".fbx"};
  return extensions;
}

namespace {

// Welded vertices and triangles, as raw bytes: vertex count, face count, doubles, ints.
std::string import_welded(const std::string& name) {
  Assimp::Importer importer;
  // Points and lines are removed; every node transform is baked into the vertices.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      name, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
    throw std::runtime_error(importer.GetErrorString());
  }
  // Weld by exact position: one index per distinct point.
  std::map<std::array<double, 3>, std::int32_t> index_of;
  std::vector<double> points;
  std::vector<std::int32_t> faces;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    std::vector<std::int32_t> welded(mesh->mNumVertices);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const std::array<double, 3> key = {p.x, p.y, p.z};
      const auto [it, inserted] =
          index_of.emplace(key, static_cast<std::int32_t>(points.size() / 3));
      if (inserted) points.insert(points.end(), key.begin(), key.end());
      welded[v] = it->second;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      const std::int32_t a = welded[face.mIndices[0]], b = welded[face.mIndices[1]],
                         c = welded[face.mIndices[2]];
      if (a == b || b == c || a == c) continue;  // collapsed by welding
      faces.insert(faces.end(), {a, b, c});
    }
  }
  const std::int64_t counts[2] = {static_cast<std::int64_t>(points.size() / 3),
                                  static_cast<std::int64_t>(faces.size() / 3)};
  std::string bytes(reinterpret_cast<const char*>(counts), sizeof counts);
  bytes.append(reinterpret_cast<const char*>(points.data()), points.size() * sizeof(double));
  bytes.append(reinterpret_cast<const char*>(faces.data()), faces.size() * sizeof(std::int32_t));
  return bytes;
}

}  // namespace

TriangleMesh load_mesh_file(const fs::path& path) {
  const std::string name = path.string();
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    throw FileError(fmt::format("mesh file '{}': no such file", name));
  }
  // assimp runs in a child process: some malformed files crash it or exhaust memory.
  std::string bytes;
  try {
    bytes = run_isolated([&] { return import_welded(name); });
  } catch (const std::runtime_error& e) {
    throw FileError(fmt::format("mesh file '{}': cannot read it ({})", name, e.what()));
  }
  std::int64_t counts[2];
  std::memcpy(counts, bytes.data(), sizeof counts);
  const auto* points = reinterpret_cast<const double*>(bytes.data() + sizeof counts);
  const auto* faces = reinterpret_cast<const std::int32_t*>(points + 3 * counts[0]);
  if (counts[1] == 0) {
    throw MeshError(
        fmt::format("mesh file '{}': no triangles (points or lines only, or empty)", name));
  }
  // Keep only the vertices that faces use: every vertex becomes a graph node.
  std::vector<int> renumber(counts[0], -1);
  int used = 0;
  for (std::int64_t i = 0; i < 3 * counts[1]; ++i)
    if (renumber[faces[i]] < 0) renumber[faces[i]] = used++;
  Points vertices(used, 3);
  for (std::int64_t v = 0; v < counts[0]; ++v) {
    if (renumber[v] >= 0)
      vertices.row(renumber[v]) << points[3 * v], points[3 * v + 1], points[3 * v + 2];
  }
  Triangles triangles(counts[1], 3);
  for (std::int64_t i = 0; i < 3 * counts[1]; ++i) triangles(i / 3, i % 3) = renumber[faces[i]];
  MeshOptions options;
  options.degenerate_faces = DegenerateFaces::kDrop;
  return TriangleMesh(name, std::move(vertices), std::move(triangles), options);
}

std::vector<fs::path> list_mesh_files(const fs::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) {
    throw FileError(fmt::format("asset folder '{}': not a readable folder", folder.string()));
  }
  std::vector<fs::path> files;
  fs::directory_iterator it(folder, error);
  if (error) {
    throw FileError(
        fmt::format("asset folder '{}': cannot list it ({})", folder.string(), error.message()));
  }
  for (const fs::directory_entry& entry : it) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
    const auto& known = mesh_file_extensions();
    if (entry.is_regular_file() && std::find(known.begin(), known.end(), extension) != known.end())
      files.push_back(entry.path());
  }
  if (files.empty()) {
    throw FileError(fmt::format("asset folder '{}': no mesh files ({})", folder.string(),
                                fmt::join(mesh_file_extensions(), ", ")));
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace fignet::bullet
