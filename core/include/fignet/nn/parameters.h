// Flat parameter storage: every tensor of a network is a named view into one float array, so the
// optimizer, gradient averaging and model files handle all weights as a single buffer.
#pragma once

#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include "fignet/nn/buffer.h"

namespace fignet {

struct TensorInfo {
  std::string name;
  int rows = 0, cols = 0;
  size_t offset = 0;
  size_t size() const { return static_cast<size_t>(rows) * cols; }
};

// How a tensor starts before training.
enum class Init {
  kFanIn,  // truncated normal (±2σ), σ = 1/sqrt(rows): variance-preserving for a Linear weight
  kZeros,
  kOnes,
};

class ParameterLayout {
 public:
  // Registers a rows x cols tensor and returns its offset in the flat array.
  size_t add(std::string name, int rows, int cols, Init init);
  const std::vector<TensorInfo>& tensors() const { return tensors_; }
  size_t size() const { return size_; }
  // Fills `values` (resized to size()) with every tensor's initial values, from `seed`.
  void initialize(std::vector<float>& values, std::uint64_t seed) const;

 private:
  std::vector<TensorInfo> tensors_;
  std::vector<Init> inits_;
  size_t size_ = 0;
};

inline ConstMatrixView tensor(const float* params, size_t offset, int rows, int cols) {
  return {params + offset, rows, cols};
}
inline MatrixView tensor(float* params, size_t offset, int rows, int cols) {
  return {params + offset, rows, cols};
}

}  // namespace fignet
