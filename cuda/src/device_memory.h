// Device storage that keeps its capacity across calls (as fignet::Buffer does on the host), and
// the checks that turn CUDA and cuBLAS failures into exceptions naming the call.
#pragma once

#include <cublas_v2.h>
#include <cuda_runtime.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "fignet/cuda/cuda_backend.h"
#include "kernels.h"

namespace fignet::cuda {

inline void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) {
    throw DeviceError(fmt::format("CUDA: {} failed: {}", what, cudaGetErrorString(status)));
  }
}

inline void check(cublasStatus_t status, const char* what) {
  if (status != CUBLAS_STATUS_SUCCESS) {
    throw DeviceError(fmt::format("cuBLAS: {} failed: {}", what, cublasGetStatusString(status)));
  }
}

// Grow-only device array; contents are not kept when it grows.
template <class T>
class DeviceArray {
 public:
  DeviceArray() = default;
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
  DeviceArray(DeviceArray&& other) noexcept : data_(other.data_), capacity_(other.capacity_) {
    other.data_ = nullptr, other.capacity_ = 0;
  }
  ~DeviceArray() {
    if (data_) cudaFree(data_);
  }
  T* reserve(size_t count) {
    if (count > capacity_) {
      if (data_) check(cudaFree(data_), "cudaFree");
      data_ = nullptr;
      capacity_ = 0;
      check(cudaMalloc(&data_, count * sizeof(T)), "cudaMalloc");
      capacity_ = count;
    }
    return data_;
  }
  // Copies `count` elements from the host (ordered on `stream`).
  T* upload(const T* host, size_t count, cudaStream_t stream) {
    reserve(std::max<size_t>(count, 1));
    if (count > 0) {
      check(cudaMemcpyAsync(data_, host, count * sizeof(T), cudaMemcpyHostToDevice, stream),
            "cudaMemcpyAsync (to device)");
    }
    return data_;
  }
  T* data() const { return data_; }

 private:
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

// A device Buffer: the last view's shape is remembered, as fignet::Buffer does.
class DeviceBuffer {
 public:
  DeviceMatrix view(int rows, int cols) {
    rows_ = rows, cols_ = cols;
    float* data = storage_.reserve(std::max<size_t>(size_t(rows) * cols, 1));
    return {data, rows, cols, cols};
  }
  DeviceMatrix zeros(int rows, int cols, cudaStream_t stream) {
    DeviceMatrix m = view(rows, cols);
    if (rows > 0 && cols > 0) {
      check(cudaMemsetAsync(m.data, 0, size_t(rows) * cols * sizeof(float), stream),
            "cudaMemsetAsync");
    }
    return m;
  }
  DeviceMatrix get() const { return {storage_.data(), rows_, cols_, cols_}; }

 private:
  DeviceArray<float> storage_;
  int rows_ = 0, cols_ = 0;
};

}  // namespace fignet::cuda
