// Shared pieces of the Python module: numpy conversions that check shapes and raise ValueError
// naming the argument, and the function that registers each part of the module.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <span>

#include "fignet/data/trajectory.h"
#include "fignet/geometry/types.h"

namespace fignet::python {

namespace py = pybind11;

// Float64 C-ordered arrays; double_array converts anything numpy can (an empty handle, with
// numpy's error cleared, where it cannot).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
inline DoubleArray double_array(const py::handle& values) {
  return DoubleArray::ensure(values);
}

// Float arrays of shape (n, 3) as Points, and integer arrays of shape (n, 3) as triangles; any
// other shape or a non-numeric array raises ValueError naming `what`.
Points to_points(const py::handle& array, const char* what);
Triangles to_triangles(const py::handle& array, const char* what);
// Three numbers (a sequence or an array) as a vector.
Vec3 to_vec3(const py::handle& values, const char* what);
// Four numbers (w, x, y, z) as a unit quaternion; ValueError for a zero or non-finite one.
Eigen::Quaterniond to_quaternion(const py::handle& values, const char* what);

// Quaternions as the module writes them: (w, x, y, z) at `out`, and read back (not normalised).
void write_wxyz(const Eigen::Quaterniond& q, double* out);
Eigen::Quaterniond read_wxyz(const double* in);

// Copies into new numpy arrays.
py::array_t<double> points_array(const Points& points);
py::array_t<double> vec3_array(const Vec3& v);
// Poses as (n, 3) positions and (n, 4) quaternions (w, x, y, z).
py::array_t<double> positions_array(std::span<const Pose> poses);
py::array_t<double> quaternions_array(std::span<const Pose> poses);

// The module's parts, registered in this order by module.cpp.
void bind_errors(py::module_& m);
void bind_data(py::module_& m);
void bind_models(py::module_& m);
void bind_evaluation(py::module_& m);
void bind_scene(py::module_& m);

}  // namespace fignet::python
