// The CUDA kernels of the network's device pass, behind plain C++ launchers so that the code
// which drives them (cuda_network.cpp) compiles without nvcc. Matrices are row-major with a
// leading dimension `ld` (floats between rows), as in the CPU path.
#pragma once

#include <cstdint>

#include <cuda_runtime.h>

namespace fignet::cuda {

struct DeviceMatrix {
  float* data = nullptr;
  int rows = 0, cols = 0, ld = 0;
  DeviceMatrix columns(int first, int count) const { return {data + first, rows, count, ld}; }
};

// Index e of an edge list reads index[e * stride + offset] (stride 3: the j-th of a face triplet).
struct DeviceIndex {
  const std::int32_t* data = nullptr;
  int count = 0, stride = 1, offset = 0;
};

// Rows grouped by the node they go to: rows[offsets[i] .. offsets[i+1]) of `rows` are the edge
// rows whose index is node i, in increasing order (a deterministic segment sum).
struct DeviceSegments {
  const std::int32_t* offsets = nullptr;  // nodes + 1
  const std::int32_t* rows = nullptr;     // edge rows, grouped by node
  int nodes = 0;
};

// out = (in − mean) ⊙ inv_std per column.
void normalize(const float* in, const float* mean, const float* inv_std, int rows, int cols,
               float* out, cudaStream_t stream);
// dst = max(src + bias, 0) (src may equal dst).
void bias_relu(DeviceMatrix src, const float* bias, DeviceMatrix dst, cudaStream_t stream);
// m += bias.
void add_bias(DeviceMatrix m, const float* bias, cudaStream_t stream);
// LayerNorm of each row of m in place: x̂ = (m − μ)/sqrt(σ² + ε) into normalized, 1/σ into
// inv_std, m = scale ⊙ x̂ + offset.
void layer_norm_forward(DeviceMatrix m, const float* scale, const float* offset, float epsilon,
                        float* normalized, float* inv_std, cudaStream_t stream);
// d_pre = inv_std·(dx̂ − mean(dx̂) − x̂·mean(dx̂⊙x̂)), dx̂ = d_out ⊙ scale, and
// product = d_out ⊙ x̂ (for the scale's gradient).
void layer_norm_backward(DeviceMatrix d_out, const float* normalized, const float* inv_std,
                         const float* scale, float* d_pre, float* product, cudaStream_t stream);
// d ⊙= (activation > 0).
void relu_mask(DeviceMatrix d, const float* activation, cudaStream_t stream);
// out.row(e) += src.row(index[e]).
void gather_add(DeviceMatrix src, DeviceIndex index, DeviceMatrix out, cudaStream_t stream);
// out.row(i) (+)= Σ src.row(r) over the rows r of segment i; overwrites unless accumulate.
void segment_sum(DeviceMatrix src, DeviceSegments segments, DeviceMatrix out, bool accumulate,
                 cudaStream_t stream);
// y += x (n floats).
void add(const float* x, float* y, std::int64_t n, cudaStream_t stream);
// Every entry of m set to `value`.
void fill(DeviceMatrix m, float value, cudaStream_t stream);

}  // namespace fignet::cuda
