#include "fignet/bullet/mesh_file.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cstring>
#include <stdexcept>

#include "fignet/error.h"
#include "isolated_call.h"
#include "mesh_assembler.h"

namespace fignet::bullet {

namespace fs = std::filesystem;

const std::vector<std::string>& mesh_file_extensions() {
  static const std::vector<std::string> extensions = {".obj", ".stl", ".ply", ".gltf",
                                                      ".glb", ".off", ".dae", ".fbx"};
  return extensions;
}

namespace {

// The file's triangles as raw bytes, nine doubles each (welding happens in the parent).
std::string import_triangles(const std::string& name) {
  Assimp::Importer importer;
  // Points and lines are removed; every node transform is baked into the vertices.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      name, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
    throw std::runtime_error(importer.GetErrorString());
  }
  std::vector<double> corners;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) {
        const aiVector3D& p = mesh->mVertices[face.mIndices[k]];
        corners.insert(corners.end(), {p.x, p.y, p.z});
      }
    }
  }
  return std::string(reinterpret_cast<const char*>(corners.data()),
                     corners.size() * sizeof(double));
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
    bytes = run_isolated([&] { return import_triangles(name); });
  } catch (const std::runtime_error& e) {
    throw FileError(fmt::format("mesh file '{}': cannot read it ({})", name, e.what()));
  }
  std::vector<double> corners(bytes.size() / sizeof(double));
  std::memcpy(corners.data(), bytes.data(), corners.size() * sizeof(double));
  // Welded by position: exporters split corners by normal or texture coordinate.
  MeshAssembler assembler;
  for (size_t i = 0; i + 9 <= corners.size(); i += 9) {
    assembler.triangle(Vec3(corners[i], corners[i + 1], corners[i + 2]),
                       Vec3(corners[i + 3], corners[i + 4], corners[i + 5]),
                       Vec3(corners[i + 6], corners[i + 7], corners[i + 8]));
  }
  if (assembler.empty()) {
    throw MeshError(
        fmt::format("mesh file '{}': no triangles (points or lines only, or empty)", name));
  }
  return assembler.finish(name);
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
