// Internal helpers over HDF5's C++ API: nested paths, typed attributes and datasets, errors that
// name the file and the object, and atomic writes (temporary file, then rename).
#pragma once

#include <H5Cpp.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace fignet::hdf5 {

// Every object this library writes is created without the modification time HDF5 stamps on it by
// default, so the same contents give the same bytes: data, models and checkpoints written twice
// compare equal with cmp or a checksum.
H5::Group create_group(const H5::Group& parent, const std::string& name);
H5::DataSet create_dataset(const H5::Group& parent, const std::string& name,
                           const H5::DataType& type, const H5::DataSpace& space);

// Opens (creating as needed) every group along "a/b/c" below `root`.
H5::Group make_groups(H5::Group root, const std::string& path);
bool exists(const H5::Group& root, const std::string& path);

void write_attribute(H5::H5Object& object, const std::string& name, double value);
void write_attribute(H5::H5Object& object, const std::string& name, long long value);
void write_attribute(H5::H5Object& object, const std::string& name, const std::string& value);
double read_double(const H5::H5Object& object, const std::string& name);
long long read_integer(const H5::H5Object& object, const std::string& name);
std::string read_string(const H5::H5Object& object, const std::string& name);
// An attribute added to a format after its first files: `absent` (what those files were made
// with) when the file has none.
long long read_integer_or(const H5::H5Object& object, const std::string& name, long long absent);
double read_double_or(const H5::H5Object& object, const std::string& name, double absent);

// Row-major datasets of floats or doubles with the given shape.
void write_floats(H5::Group& group, const std::string& path, const float* data,
                  const std::vector<hsize_t>& shape);
void write_doubles(H5::Group& group, const std::string& path, const double* data,
                   const std::vector<hsize_t>& shape);
// The dataset's dimensions; throws FileError (prefixed by `where`) when they need more bytes than
// the file stores for it (a corrupt header).
std::vector<hsize_t> shape_of(const H5::DataSet& dataset, const std::string& where = "");
void read_floats(const H5::DataSet& dataset, float* out);
void read_doubles(const H5::DataSet& dataset, double* out);

// Runs `write` on a temporary file beside `path` and renames it into place; on any failure the
// temporary file is removed and nothing is left at `path`. HDF5 errors become FileError.
void write_atomically(const std::filesystem::path& path, const std::string& what,
                      const std::function<void(H5::H5File&)>& write);
// Opens `path` read-only; throws FileError naming it when it is missing or not HDF5.
H5::H5File open_for_reading(const std::filesystem::path& path, const std::string& what);

}  // namespace fignet::hdf5
