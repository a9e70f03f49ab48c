// The objects of an HDF5 file that carry a time stamp; files this library writes have none, so
// the same contents give the same bytes.
#pragma once

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace fignet::testing {

inline std::vector<std::string> objects_with_time_stamps(const std::filesystem::path& path) {
  std::vector<std::string> stamped;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) {
    ADD_FAILURE() << "cannot open " << path;
    return {"(unreadable)"};
  }
  H5Ovisit2(
      file, H5_INDEX_NAME, H5_ITER_NATIVE,
      [](hid_t, const char* name, const H5O_info_t* info, void* out) -> herr_t {
        if (info->atime != 0 || info->mtime != 0 || info->ctime != 0 || info->btime != 0) {
          static_cast<std::vector<std::string>*>(out)->push_back(name);
        }
        return 0;
      },
      &stamped, H5O_INFO_TIME);
  H5Fclose(file);
  return stamped;
}

}  // namespace fignet::testing
