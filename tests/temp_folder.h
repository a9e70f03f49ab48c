// A temporary folder per test (named after the test and the process), removed afterwards, and a
// Wavefront OBJ writer for mesh fixtures.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "fignet/geometry/mesh.h"

namespace fignet::testing {

class TempFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("fignet_") + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path write_obj(const TriangleMesh& mesh, const std::string& name) const {
    const std::filesystem::path path = dir_ / name;
    std::ofstream out(path);
    out.precision(17);
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      out << "v " << mesh.vertices()(v, 0) << ' ' << mesh.vertices()(v, 1) << ' '
          << mesh.vertices()(v, 2) << '\n';
    }
    for (int f = 0; f < mesh.num_faces(); ++f) {
      out << "f " << mesh.faces()(f, 0) + 1 << ' ' << mesh.faces()(f, 1) + 1 << ' '
          << mesh.faces()(f, 2) + 1 << '\n';
    }
    return path;
  }

  std::filesystem::path dir_;
};

}  // namespace fignet::testing
