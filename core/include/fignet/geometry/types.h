// Dense row-major matrix types shared by geometry and graph code.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace fignet {

// Positions are kept in double precision: features are differences of nearby points, and a scene
// far from the origin (1 km) would lose millimetres in float32 before the subtraction.
using Vec3 = Eigen::Vector3d;
using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using EdgeList = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 2, Eigen::RowMajor>;

// Features, latents and weights are float32, row-major: one row per node or edge.
using RowMatrixXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// Storage aligned for SIMD: Eigen's vectorised reductions peel scalars until the data is aligned,
// so an address-dependent alignment would change the summation order and break bit-exact
// determinism between runs and between two trainers in one process.
using AlignedFloats = std::vector<float, Eigen::aligned_allocator<float>>;

}  // namespace fignet
