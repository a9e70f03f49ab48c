#include "fignet/nn/parameters.h"

#include <cmath>

namespace fignet {

size_t ParameterLayout::add(std::string name, int rows, int cols, Init init) {
  TensorInfo info{std::move(name), rows, cols, size_};
  size_ += info.size();
  tensors_.push_back(std::move(info));
  inits_.push_back(init);
  return tensors_.back().offset;
}

void ParameterLayout::initialize(std::vector<float>& values, std::uint64_t seed) const {
  values.assign(size_, 0.0f);
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  for (size_t t = 0; t < tensors_.size(); ++t) {
    const TensorInfo& info = tensors_[t];
    float* out = values.data() + info.offset;
    switch (inits_[t]) {
      case Init::kZeros:
        break;
      case Init::kOnes:
        std::fill(out, out + info.size(), 1.0f);
        break;
      case Init::kFanIn: {
        const float sigma = 1.0f / std::sqrt(static_cast<float>(info.rows));
        for (size_t i = 0; i < info.size(); ++i) {
          float z;
          do z = normal(rng);
          while (std::abs(z) > 2.0f);
          out[i] = sigma * z;
        }
        break;
      }
    }
  }
}

}  // namespace fignet
