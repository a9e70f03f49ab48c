// A FIGNet model: config, network structure, parameters and normaliser statistics. Immutable once
// built, so one model can be shared by any number of predictors and threads.
#pragma once

#include <vector>

#include "fignet/model/network.h"

namespace fignet {

class Model {
 public:
  // A fresh model, parameters initialised from config.seed, empty statistics.
  explicit Model(const ModelConfig& config);
  // A trained model. Throws ConfigError when the parameter count or a normaliser's width does not
  // match the config.
  Model(const ModelConfig& config, std::vector<float> parameters, Normalizers normalizers);

  const ModelConfig& config() const { return network_.config(); }
  const Network& network() const { return network_; }
  const std::vector<float>& parameters() const { return parameters_; }
  const Normalizers& normalizers() const { return normalizers_; }

 private:
  Network network_;
  std::vector<float> parameters_;
  Normalizers normalizers_;
};

}  // namespace fignet
