#include "hdf5_util.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <sstream>

#include "fignet/error.h"

namespace fignet::hdf5 {

namespace {

// HDF5 prints its own error stack to stderr unless told not to; our exceptions say it better.
void silence_hdf5() {
  static const bool silenced = [] {
    H5::Exception::dontPrint();
    return true;
  }();
  (void)silenced;
}

std::vector<std::string> split(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream stream(path);
  for (std::string part; std::getline(stream, part, '/');) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

}  // namespace

H5::Group create_group(const H5::Group& parent, const std::string& name) {
  // HDF5's C++ API of Debian's 1.10 takes no group creation properties: create through C.
  const hid_t properties = H5Pcreate(H5P_GROUP_CREATE);
  H5Pset_obj_track_times(properties, false);
  const hid_t id = H5Gcreate2(parent.getId(), name.c_str(), H5P_DEFAULT, properties, H5P_DEFAULT);
  H5Pclose(properties);
  if (id < 0) throw H5::GroupIException("create_group", "cannot create group '" + name + "'");
  H5::Group group(id);  // holds a reference of its own
  H5Gclose(id);
  return group;
}

H5::DataSet create_dataset(const H5::Group& parent, const std::string& name,
                           const H5::DataType& type, const H5::DataSpace& space) {
  H5::DSetCreatPropList properties;
  H5Pset_obj_track_times(properties.getId(), false);
  return parent.createDataSet(name, type, space, properties);
}

H5::Group make_groups(H5::Group root, const std::string& path) {
  H5::Group group = root;
  for (const std::string& part : split(path)) {
    group = group.nameExists(part) ? group.openGroup(part) : create_group(group, part);
  }
  return group;
}

bool exists(const H5::Group& root, const std::string& path) {
  H5::Group group = root;
  const auto parts = split(path);
  for (size_t i = 0; i < parts.size(); ++i) {
    if (!group.nameExists(parts[i])) return false;
    if (i + 1 < parts.size()) {
      if (group.childObjType(parts[i]) != H5O_TYPE_GROUP) return false;
      group = group.openGroup(parts[i]);
    }
  }
  return true;
}

void write_attribute(H5::H5Object& object, const std::string& name, double value) {
  object.createAttribute(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace())
      .write(H5::PredType::NATIVE_DOUBLE, &value);
}

void write_attribute(H5::H5Object& object, const std::string& name, long long value) {
  object.createAttribute(name, H5::PredType::NATIVE_LLONG, H5::DataSpace())
      .write(H5::PredType::NATIVE_LLONG, &value);
}

void write_attribute(H5::H5Object& object, const std::string& name, const std::string& value) {
  const H5::StrType type(H5::PredType::C_S1, value.empty() ? 1 : value.size());
  object.createAttribute(name, type, H5::DataSpace()).write(type, value);
}

double read_double(const H5::H5Object& object, const std::string& name) {
  double value = 0;
  object.openAttribute(name).read(H5::PredType::NATIVE_DOUBLE, &value);
  return value;
}

long long read_integer(const H5::H5Object& object, const std::string& name) {
  long long value = 0;
  object.openAttribute(name).read(H5::PredType::NATIVE_LLONG, &value);
  return value;
}

long long read_integer_or(const H5::H5Object& object, const std::string& name, long long absent) {
  return object.attrExists(name) ? read_integer(object, name) : absent;
}

double read_double_or(const H5::H5Object& object, const std::string& name, double absent) {
  return object.attrExists(name) ? read_double(object, name) : absent;
}

std::string read_string(const H5::H5Object& object, const std::string& name) {
  const H5::Attribute attribute = object.openAttribute(name);
  std::string value;
  attribute.read(attribute.getStrType(), value);
  return value;
}

template <class T>
void write_dataset(H5::Group& group, const std::string& path, const T* data,
                   const std::vector<hsize_t>& shape, const H5::PredType& memory,
                   const H5::PredType& file) {
  const auto slash = path.rfind('/');
  H5::Group parent = slash == std::string::npos ? group : make_groups(group, path.substr(0, slash));
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const H5::DataSpace space(static_cast<int>(shape.size()), shape.data());
  create_dataset(parent, name, file, space).write(data, memory);
}

void write_floats(H5::Group& group, const std::string& path, const float* data,
                  const std::vector<hsize_t>& shape) {
  write_dataset(group, path, data, shape, H5::PredType::NATIVE_FLOAT, H5::PredType::IEEE_F32LE);
}

void write_doubles(H5::Group& group, const std::string& path, const double* data,
                   const std::vector<hsize_t>& shape) {
  write_dataset(group, path, data, shape, H5::PredType::NATIVE_DOUBLE, H5::PredType::IEEE_F64LE);
}

std::vector<hsize_t> shape_of(const H5::DataSet& dataset, const std::string& where) {
  const H5::DataSpace space = dataset.getSpace();
  std::vector<hsize_t> shape(space.getSimpleExtentNdims());
  space.getSimpleExtentDims(shape.data());
  // A corrupt header can declare any size; this library writes every dataset whole, so more
  // elements than the file stores is a damaged file, not a reason to allocate terabytes.
  long double elements = 1;
  for (hsize_t n : shape) elements *= static_cast<long double>(n);
  const long double needed = elements * dataset.getDataType().getSize();
  const hsize_t stored = dataset.getStorageSize();
  if (needed > static_cast<long double>(stored)) {
    throw FileError(fmt::format(
        "{}{}dataset '{}' declares [{}] but the file stores {} bytes of "
        "it: the file is truncated or corrupt",
        where, where.empty() ? "" : ": ", dataset.getObjName(), fmt::join(shape, ", "), stored));
  }
  return shape;
}

void read_floats(const H5::DataSet& dataset, float* out) {
  dataset.read(out, H5::PredType::NATIVE_FLOAT);
}

void read_doubles(const H5::DataSet& dataset, double* out) {
  dataset.read(out, H5::PredType::NATIVE_DOUBLE);
}

void write_atomically(const std::filesystem::path& path, const std::string& what,
                      const std::function<void(H5::H5File&)>& write) {
  silence_hdf5();
  std::filesystem::path temporary = path;
  temporary += fmt::format(".tmp-{}", ::getpid());
  try {
    {
      H5::FileCreatPropList properties;  // the root group without a time stamp either
      H5Pset_obj_track_times(properties.getId(), false);
      H5::H5File file(temporary.string(), H5F_ACC_TRUNC, properties);
      write(file);
    }  // closed (and flushed) before the rename
    std::filesystem::rename(temporary, path);
  } catch (const H5::Exception& e) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw FileError(
        fmt::format("{} '{}': cannot write ({})", what, path.string(), e.getDetailMsg()));
  } catch (const std::filesystem::filesystem_error& e) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw FileError(fmt::format("{} '{}': cannot write ({})", what, path.string(), e.what()));
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

H5::H5File open_for_reading(const std::filesystem::path& path, const std::string& what) {
  silence_hdf5();
  if (!std::filesystem::exists(path)) {
    throw FileError(fmt::format("{} '{}': no such file", what, path.string()));
  }
  try {
    return H5::H5File(path.string(), H5F_ACC_RDONLY);
  } catch (const H5::Exception&) {
    throw FileError(
        fmt::format("{} '{}': not a readable HDF5 file (truncated or of another "
                    "format)",
                    what, path.string()));
  }
}

}  // namespace fignet::hdf5
