#include "fignet/io/trajectory_file.h"

#include <functional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "fignet/error.h"
#include "hdf5_util.h"

namespace fignet {

namespace {

constexpr const char* kFormat = "fignet-trajectories";
constexpr const char* kWhat = "trajectory file";

using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

hsize_t size(Eigen::Index n) {
  return static_cast<hsize_t>(n);
}

void write_object(H5::Group group, const TrajectoryObject& object) {
  using hdf5::write_attribute;
  const TriangleMesh& mesh = *object.mesh;
  write_attribute(group, "name", mesh.name());
  write_attribute(group, "mass", object.properties.mass);
  write_attribute(group, "friction", object.properties.friction);
  write_attribute(group, "restitution", object.properties.restitution);
  write_attribute(group, "kinematic", static_cast<long long>(object.kinematic));
  if (object.inertia) {
    for (int k = 0; k < 3; ++k)
      write_attribute(group, fmt::format("inertia_{}", "xyz"[k]), (*object.inertia)[k]);
  }
  hdf5::write_doubles(group, "rest_vertices", mesh.vertices().data(),
                      {size(mesh.num_vertices()), 3});
  const H5::DataSpace space(2, std::vector<hsize_t>{size(mesh.num_faces()), 3}.data());
  hdf5::create_dataset(group, "faces", H5::PredType::STD_I32LE, space)
      .write(mesh.faces().data(), H5::PredType::NATIVE_INT32);
  const hsize_t frames = object.poses.size();
  Rows positions(frames, 3), orientations(frames, 4);
  for (hsize_t f = 0; f < frames; ++f) {
    const Pose& pose = object.poses[f];
    positions.row(f) = pose.position.transpose();
    orientations.row(f) << pose.orientation.w(), pose.orientation.x(), pose.orientation.y(),
        pose.orientation.z();
  }
  hdf5::write_doubles(group, "position", positions.data(), {frames, 3});
  hdf5::write_doubles(group, "orientation", orientations.data(), {frames, 4});
  for (auto [name, values] : {std::pair("linear_velocity", &object.linear_velocities),
                              std::pair("angular_velocity", &object.angular_velocities)}) {
    if (values->empty()) continue;
    Rows rows(values->size(), 3);
    for (size_t f = 0; f < values->size(); ++f) rows.row(f) = (*values)[f].transpose();
    hdf5::write_doubles(group, name, rows.data(), {values->size(), 3});
  }
}

void write_trajectory(H5::Group group, const Trajectory& t) {
  using hdf5::write_attribute;
  write_attribute(group, "time_step", t.time_step);
  for (int i = 0; i < 3; ++i)
    write_attribute(group, fmt::format("gravity_{}", "xyz"[i]), t.gravity[i]);
  write_attribute(group, "seed", static_cast<long long>(t.seed));
  write_attribute(group, "has_floor", static_cast<long long>(t.floor.has_value()));
  if (t.floor) {
    write_attribute(group, "floor_height", t.floor->height);
    write_attribute(group, "floor_friction", t.floor->properties.friction);
    write_attribute(group, "floor_restitution", t.floor->properties.restitution);
  }
  write_attribute(group, "num_objects", static_cast<long long>(t.objects.size()));
  for (size_t o = 0; o < t.objects.size(); ++o) {
    write_object(hdf5::create_group(group, fmt::format("object_{}", o)), t.objects[o]);
  }
}

// Reads a [rows, cols] float64 dataset, checking its shape.
Rows read_rows(const H5::Group& group, const std::string& name, hsize_t rows, hsize_t cols,
               const std::string& where) {
  if (!group.nameExists(name))
    throw FileError(fmt::format("{}: missing dataset '{}'", where, name));
  const H5::DataSet dataset = group.openDataSet(name);
  const auto shape = hdf5::shape_of(dataset, where);
  if (shape.size() != 2 || (rows && shape[0] != rows) || shape[1] != cols) {
    throw FileError(fmt::format("{}: dataset '{}' has shape [{}], expected [{}, {}]", where, name,
                                fmt::join(shape, ", "), rows ? std::to_string(rows) : "n", cols));
  }
  Rows out(shape[0], cols);
  hdf5::read_doubles(dataset, out.data());
  return out;
}

TrajectoryObject read_object(const H5::Group& group, const std::string& where) {
  TrajectoryObject object;
  object.properties = {hdf5::read_double(group, "mass"), hdf5::read_double(group, "friction"),
                       hdf5::read_double(group, "restitution")};
  object.kinematic = hdf5::read_integer(group, "kinematic") != 0;
  if (group.attrExists("inertia_x")) {
    Vec3 inertia;
    for (int k = 0; k < 3; ++k)
      inertia[k] = hdf5::read_double(group, fmt::format("inertia_{}", "xyz"[k]));
    if (!inertia.allFinite() || (inertia.array() < 0.0).any()) {
      throw FileError(fmt::format("{}: inertia ({}, {}, {}) must be finite and >= 0", where,
                                  inertia.x(), inertia.y(), inertia.z()));
    }
    object.inertia = inertia;
  }
  Points vertices = read_rows(group, "rest_vertices", 0, 3, where);
  if (!group.nameExists("faces"))
    throw FileError(fmt::format("{}: missing dataset 'faces'", where));
  const H5::DataSet faces_set = group.openDataSet("faces");
  const auto face_shape = hdf5::shape_of(faces_set, where);
  if (face_shape.size() != 2 || face_shape[1] != 3) {
    throw FileError(fmt::format("{}: dataset 'faces' is not [n, 3]", where));
  }
  Triangles faces(face_shape[0], 3);
  faces_set.read(faces.data(), H5::PredType::NATIVE_INT32);
  try {
    object.mesh = std::make_shared<const TriangleMesh>(hdf5::read_string(group, "name"),
                                                       std::move(vertices), std::move(faces));
  } catch (const MeshError& e) {
    throw FileError(fmt::format("{}: {}", where, e.what()));
  }
  const Rows positions = read_rows(group, "position", 0, 3, where);
  const Rows orientations = read_rows(group, "orientation", positions.rows(), 4, where);
  for (Eigen::Index f = 0; f < positions.rows(); ++f) {
    Pose pose;
    pose.position = positions.row(f).transpose();
    pose.orientation = Eigen::Quaterniond(orientations(f, 0), orientations(f, 1),
                                          orientations(f, 2), orientations(f, 3));
    if (!pose.position.allFinite() || std::abs(pose.orientation.norm() - 1.0) > 1e-6) {
      throw FileError(
          fmt::format("{}: frame {} has a non-finite position or a non-unit "
                      "orientation",
                      where, f));
    }
    object.poses.push_back(pose);
  }
  for (auto [name, values] : {std::pair("linear_velocity", &object.linear_velocities),
                              std::pair("angular_velocity", &object.angular_velocities)}) {
    if (!group.nameExists(name)) continue;
    const Rows rows = read_rows(group, name, positions.rows(), 3, where);
    for (Eigen::Index f = 0; f < rows.rows(); ++f) values->push_back(rows.row(f).transpose());
  }
  return object;
}

Trajectory read_trajectory(const H5::Group& group, const std::string& where) {
  Trajectory t;
  t.time_step = hdf5::read_double(group, "time_step");
  for (int i = 0; i < 3; ++i)
    t.gravity[i] = hdf5::read_double(group, fmt::format("gravity_{}", "xyz"[i]));
  t.seed = static_cast<std::uint64_t>(hdf5::read_integer(group, "seed"));
  if (hdf5::read_integer(group, "has_floor")) {
    Floor floor;
    floor.height = hdf5::read_double(group, "floor_height");
    floor.properties.friction = hdf5::read_double(group, "floor_friction");
    floor.properties.restitution = hdf5::read_double(group, "floor_restitution");
    t.floor = floor;
  }
  const long long objects = hdf5::read_integer(group, "num_objects");
  for (long long o = 0; o < objects; ++o) {
    const std::string name = fmt::format("object_{}", o);
    if (!group.nameExists(name))
      throw FileError(fmt::format("{}: missing group '{}'", where, name));
    t.objects.push_back(read_object(group.openGroup(name), where + "/" + name));
  }
  try {
    t.validate();
  } catch (const ConfigError& e) {
    throw FileError(fmt::format("{}: {}", where, e.what()));
  }
  return t;
}

}  // namespace

void write_trajectories(const std::filesystem::path& path, std::span<const Trajectory> trajectories,
                        const DatasetInfo& info) {
  hdf5::write_atomically(path, kWhat, [&](H5::H5File& file) {
    H5::Group root = file.openGroup("/");
    hdf5::write_attribute(root, "format", std::string(kFormat));
    hdf5::write_attribute(root, "version", kTrajectoryFileVersion);
    hdf5::write_attribute(root, "preset", info.preset);
    hdf5::write_attribute(root, "generator_version", info.generator_version);
    hdf5::write_attribute(root, "seed", static_cast<long long>(info.seed));
    hdf5::write_attribute(root, "stacks", static_cast<long long>(info.stacks));
    hdf5::write_attribute(root, "min_stack_levels", static_cast<long long>(info.min_stack_levels));
    hdf5::write_attribute(root, "max_stack_levels", static_cast<long long>(info.max_stack_levels));
    // Only files with piles say so: every other file keeps the bytes it had before piles existed
    // (the md5 sums that runs/*/README.md give for their data).
    if (info.piles > 0) {
      hdf5::write_attribute(root, "piles", static_cast<long long>(info.piles));
      hdf5::write_attribute(root, "min_pile_objects",
                            static_cast<long long>(info.min_pile_objects));
      hdf5::write_attribute(root, "max_pile_objects",
                            static_cast<long long>(info.max_pile_objects));
    }
    if (info.sphere_topped_stacks > 0.0) {
      hdf5::write_attribute(root, "sphere_topped_stacks", info.sphere_topped_stacks);
    }
    hdf5::write_attribute(root, "num_trajectories", static_cast<long long>(trajectories.size()));
    H5::Group group = hdf5::create_group(file, "trajectories");
    for (size_t i = 0; i < trajectories.size(); ++i) {
      write_trajectory(hdf5::create_group(group, fmt::format("{:06d}", i)), trajectories[i]);
    }
  });
}

namespace {

// Reads the trajectories of one file whose global index (first_index + position) `keep` accepts;
// returns how many the file holds.
long long read_file(const std::filesystem::path& path, DatasetInfo* info, long long first_index,
                    const std::function<bool(long long)>& keep, std::vector<Trajectory>& result) {
  H5::H5File file = hdf5::open_for_reading(path, kWhat);
  const std::string where = fmt::format("{} '{}'", kWhat, path.string());
  try {
    const H5::Group root = file.openGroup("/");
    if (!root.attrExists("format") || hdf5::read_string(root, "format") != kFormat) {
      throw FileError(fmt::format("{}: not a fignet trajectory file (no format = '{}' attribute)",
                                  where, kFormat));
    }
    const long long version = hdf5::read_integer(root, "version");
    if (version != kTrajectoryFileVersion) {
      throw FileError(fmt::format("{}: format version {} is not supported (this build reads {})",
                                  where, version, kTrajectoryFileVersion));
    }
    if (info) {
      info->preset = hdf5::read_string(root, "preset");
      info->generator_version = hdf5::read_string(root, "generator_version");
      info->seed = static_cast<std::uint64_t>(hdf5::read_integer(root, "seed"));
      // Files written before stacks existed hold the preset's scenes.
      info->stacks = static_cast<int>(hdf5::read_integer_or(root, "stacks", 0));
      // Files written before the levels were an option hold stacks of 1–3.
      info->min_stack_levels = static_cast<int>(hdf5::read_integer_or(root, "min_stack_levels", 1));
      info->max_stack_levels = static_cast<int>(hdf5::read_integer_or(root, "max_stack_levels", 3));
      // Files written before piles existed hold none.
      info->piles = static_cast<int>(hdf5::read_integer_or(root, "piles", 0));
      info->min_pile_objects = static_cast<int>(hdf5::read_integer_or(root, "min_pile_objects", 3));
      info->max_pile_objects = static_cast<int>(hdf5::read_integer_or(root, "max_pile_objects", 6));
      // Files written before spheres topped stacks hold none.
      info->sphere_topped_stacks = hdf5::read_double_or(root, "sphere_topped_stacks", 0.0);
    }
    const long long count = hdf5::read_integer(root, "num_trajectories");
    const H5::Group group = file.openGroup("trajectories");
    for (long long i = 0; i < count; ++i) {
      if (!keep(first_index + i)) continue;
      const std::string name = fmt::format("{:06d}", i);
      if (!group.nameExists(name)) {
        throw FileError(fmt::format("{}: missing trajectory '{}' of {}", where, name, count));
      }
      result.push_back(read_trajectory(group.openGroup(name), where + " trajectory " + name));
    }
    return count;
  } catch (const H5::Exception& e) {
    throw FileError(fmt::format("{}: cannot read ({})", where, e.getDetailMsg()));
  }
}

}  // namespace

std::vector<Trajectory> read_trajectories(const std::filesystem::path& path, DatasetInfo* info) {
  std::vector<Trajectory> result;
  read_file(
      path, info, 0, [](long long) { return true; }, result);
  return result;
}

std::vector<Trajectory> read_trajectories(const std::vector<std::filesystem::path>& paths) {
  return read_trajectories(paths, TrajectoryShare{});
}

std::vector<Trajectory> read_trajectories(const std::vector<std::filesystem::path>& paths,
                                          const TrajectoryShare& share) {
  if (share.count < 1 || share.index < 0 || share.index >= share.count) {
    throw ConfigError(fmt::format("trajectory share {} of {}", share.index, share.count));
  }
  std::vector<Trajectory> result;
  long long first = 0;
  for (const auto& path : paths) {
    first += read_file(
        path, nullptr, first, [&](long long i) { return i % share.count == share.index; }, result);
  }
  return result;
}

}  // namespace fignet
