// Dense row-major matrix types shared by geometry and graph code.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace fignet {

// Positions are kept in double precision: features are differences of nearby points, and a scene
// far from the origin (1 km) would lose millimetres in float32 before the subtraction.
using Vec3 = Eigen::Vector3d;
using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using EdgeList = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 2, Eigen::RowMajor>;

}  // namespace fignet
