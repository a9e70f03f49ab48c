// The model part of an HDF5 file, shared by model files and training checkpoints (a checkpoint is
// a model file with an extra /training group, so any checkpoint loads as a model).
#pragma once

#include <H5Cpp.h>

#include <string>

#include "fignet/model/model.h"

namespace fignet {

// Writes the format tag, config, parameters and normalisers into an open file.
void write_model_contents(H5::H5File& file, const Model& model);
// Reads them back; `where` names the file in errors. Throws FileError.
Model read_model_contents(const H5::H5File& file, const std::string& where);

}  // namespace fignet
