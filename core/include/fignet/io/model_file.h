// Model files: one versioned HDF5 file holding the config, every weight under a stable name and
// the normaliser statistics (schema in docs/model-file.md; readable with h5py).
#pragma once

#include <filesystem>

#include "fignet/model/model.h"

namespace fignet {

inline constexpr long long kModelFileVersion = 1;

// Writes `model` to a temporary file beside `path`, then renames it into place. Throws FileError.
void save_model(const Model& model, const std::filesystem::path& path);

// Throws FileError naming the file and the problem: missing, not HDF5 (truncated), another
// format or version, a missing tensor, a wrong shape, an invalid config value.
Model load_model(const std::filesystem::path& path);

}  // namespace fignet
