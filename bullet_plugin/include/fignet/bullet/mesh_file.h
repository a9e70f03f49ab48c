// Triangle meshes from files through assimp (OBJ, STL, PLY, glTF/GLB, OFF, and whatever else the
// installed assimp reads), and folders of them as asset libraries.
#pragma once

#include <filesystem>
#include <vector>

#include "fignet/geometry/mesh.h"

namespace fignet::bullet {

// The file's meshes merged into one, with node transforms applied, triangulated, vertices welded
// by position (exporters split them by normal or texture coordinate), unused vertices and
// collapsed or zero-area faces dropped, named after the file. Throws FileError naming the file
// when it is missing or assimp cannot read it, and MeshError when it holds no triangles.
TriangleMesh load_mesh_file(const std::filesystem::path& path);

// The mesh files (by extension, see mesh_file_extensions()) directly inside `folder`, sorted by
// name so a seed always picks the same asset. Throws FileError when the folder cannot be read or
// holds no mesh file.
std::vector<std::filesystem::path> list_mesh_files(const std::filesystem::path& folder);
const std::vector<std::string>& mesh_file_extensions();

}  // namespace fignet::bullet
