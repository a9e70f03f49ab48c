// `import fignet`: the compiled part of the Python package (python/fignet/__init__.py re-exports
// it). Each part of the library is bound in a file of its own.
#include "bindings.h"

#include "fignet/error.h"

namespace fignet::python {

Points to_points(const py::handle& array, const char* what) {
  const DoubleArray values = double_array(array);
  if (!values || values.ndim() != 2 || values.shape(1) != 3) {
    throw py::value_error(std::string(what) + ": expected an array of shape (n, 3) of numbers");
  }
  Points points(values.shape(0), 3);
  std::copy_n(values.data(), values.size(), points.data());
  return points;
}

Triangles to_triangles(const py::handle& array, const char* what) {
  const py::array raw = py::array::ensure(array);
  if (!raw || (raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u') || raw.ndim() != 2 ||
      raw.shape(1) != 3) {
    throw py::value_error(std::string(what) +
                          ": expected an integer array of shape (n, 3) (vertex indices)");
  }
  const auto values = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>(raw);
  Triangles faces(values.shape(0), 3);
  for (py::ssize_t i = 0; i < values.size(); ++i) {
    const std::int64_t index = values.data()[i];
    if (index < 0 || index > std::numeric_limits<std::int32_t>::max()) {
      throw py::value_error(std::string(what) + ": vertex index " + std::to_string(index) +
                            " out of range");
    }
    faces.data()[i] = static_cast<std::int32_t>(index);
  }
  return faces;
}

namespace {

// A flat array of `n` numbers from any sequence, or ValueError.
std::vector<double> numbers(const py::handle& values, py::ssize_t n, const char* what,
                            const char* shape) {
  const DoubleArray array = double_array(values);
  if (!array || array.size() != n || array.ndim() != 1) {
    throw py::value_error(std::string(what) + ": expected " + shape + " numbers");
  }
  std::vector<double> out(array.data(), array.data() + n);
  for (double x : out) {
    if (!std::isfinite(x)) throw py::value_error(std::string(what) + ": not finite");
  }
  return out;
}

}  // namespace

Vec3 to_vec3(const py::handle& values, const char* what) {
  const std::vector<double> v = numbers(values, 3, what, "3 (x, y, z)");
  return {v[0], v[1], v[2]};
}

Eigen::Quaterniond to_quaternion(const py::handle& values, const char* what) {
  const std::vector<double> v = numbers(values, 4, what, "4 (w, x, y, z)");
  Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
  if (!(q.norm() > 1e-12)) throw py::value_error(std::string(what) + ": a zero quaternion");
  return q.normalized();
}

py::array_t<double> points_array(const Points& points) {
  py::array_t<double> out({points.rows(), Eigen::Index{3}});
  std::copy_n(points.data(), points.size(), out.mutable_data());
  return out;
}

py::array_t<double> vec3_array(const Vec3& v) {
  py::array_t<double> out(3);
  std::copy_n(v.data(), 3, out.mutable_data());
  return out;
}

void write_wxyz(const Eigen::Quaterniond& q, double* out) {
  out[0] = q.w(), out[1] = q.x(), out[2] = q.y(), out[3] = q.z();
}

Eigen::Quaterniond read_wxyz(const double* in) {
  return {in[0], in[1], in[2], in[3]};
}

py::array_t<double> positions_array(std::span<const Pose> poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{3}});
  for (size_t i = 0; i < poses.size(); ++i) {
    std::copy_n(poses[i].position.data(), 3, out.mutable_data() + 3 * i);
  }
  return out;
}

py::array_t<double> quaternions_array(std::span<const Pose> poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}});
  for (size_t i = 0; i < poses.size(); ++i) {
    write_wxyz(poses[i].orientation, out.mutable_data() + 4 * i);
  }
  return out;
}

void bind_errors(py::module_& m) {
  // The library's errors keep their message; their Python types say what kind of input was bad.
  py::register_exception<MeshError>(m, "MeshError", PyExc_ValueError);
  py::register_exception<ConfigError>(m, "ConfigError", PyExc_ValueError);
  py::register_exception<FileError>(m, "FileError", PyExc_OSError);
}

}  // namespace fignet::python

PYBIND11_MODULE(_fignet, m) {
  using namespace fignet::python;
  m.doc() =
      "FIGNet (Face Interaction Graph Networks) for Bullet: learned rigid-body simulation. "
      "Models, trajectory files, rollouts, evaluation and a scene API.";
  m.attr("__version__") = FIGNET_VERSION;
  bind_errors(m);
  bind_data(m);
  bind_models(m);
  bind_evaluation(m);
  bind_scene(m);
}
