#include "kernels.h"

namespace fignet::cuda {

namespace {

constexpr int kThreads = 256;

int blocks_for(std::int64_t n) {
  return static_cast<int>((n + kThreads - 1) / kThreads);
}

__global__ void normalize_kernel(const float* in, const float* mean, const float* inv_std, int rows,
                                 int cols, float* out) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= std::int64_t(rows) * cols) return;
  const int c = static_cast<int>(i % cols);
  out[i] = (in[i] - mean[c]) * inv_std[c];
}

__global__ void bias_relu_kernel(DeviceMatrix src, const float* bias, DeviceMatrix dst) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= std::int64_t(src.rows) * src.cols) return;
  const int r = static_cast<int>(i / src.cols), c = static_cast<int>(i % src.cols);
  dst.data[std::int64_t(r) * dst.ld + c] =
      fmaxf(src.data[std::int64_t(r) * src.ld + c] + bias[c], 0.0f);
}

__global__ void add_bias_kernel(DeviceMatrix m, const float* bias) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= std::int64_t(m.rows) * m.cols) return;
  const int r = static_cast<int>(i / m.cols), c = static_cast<int>(i % m.cols);
  m.data[std::int64_t(r) * m.ld + c] += bias[c];
}

__device__ float warp_sum(float value) {
  for (int shift = 16; shift > 0; shift >>= 1) value += __shfl_xor_sync(0xffffffffu, value, shift);
  return value;
}

// One warp per row; lanes stride over the columns.
__global__ void layer_norm_forward_kernel(DeviceMatrix m, const float* scale, const float* offset,
                                          float epsilon, float* normalized, float* inv_std) {
  const int row = blockIdx.x * (blockDim.x / 32) + threadIdx.x / 32, lane = threadIdx.x % 32;
  if (row >= m.rows) return;
  float* x = m.data + std::int64_t(row) * m.ld;
  float* n = normalized + std::int64_t(row) * m.cols;
  float sum = 0.0f;
  for (int c = lane; c < m.cols; c += 32) sum += x[c];
  const float mean = warp_sum(sum) / m.cols;
  float squares = 0.0f;
  for (int c = lane; c < m.cols; c += 32) {
    const float d = x[c] - mean;
    n[c] = d;
    squares += d * d;
  }
  const float inv = rsqrtf(warp_sum(squares) / m.cols + epsilon);
  if (lane == 0) inv_std[row] = inv;
  for (int c = lane; c < m.cols; c += 32) {
    const float hat = n[c] * inv;
    n[c] = hat;
    x[c] = scale[c] * hat + offset[c];
  }
}

__global__ void layer_norm_backward_kernel(DeviceMatrix d_out, const float* normalized,
                                           const float* inv_std, const float* scale, float* d_pre,
                                           float* product) {
  const int row = blockIdx.x * (blockDim.x / 32) + threadIdx.x / 32, lane = threadIdx.x % 32;
  if (row >= d_out.rows) return;
  const int cols = d_out.cols;
  const float* d = d_out.data + std::int64_t(row) * d_out.ld;
  const float* n = normalized + std::int64_t(row) * cols;
  float* out = d_pre + std::int64_t(row) * cols;
  float* p = product + std::int64_t(row) * cols;
  float sum_d = 0.0f, sum_dn = 0.0f;
  for (int c = lane; c < cols; c += 32) {
    const float hat = d[c] * scale[c];
    sum_d += hat;
    sum_dn += hat * n[c];
    p[c] = d[c] * n[c];
  }
  const float mean_d = warp_sum(sum_d) / cols, mean_dn = warp_sum(sum_dn) / cols;
  const float inv = inv_std[row];
  for (int c = lane; c < cols; c += 32) out[c] = inv * (d[c] * scale[c] - mean_d - n[c] * mean_dn);
}

__global__ void relu_mask_kernel(DeviceMatrix d, const float* activation) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= std::int64_t(d.rows) * d.cols) return;
  const int r = static_cast<int>(i / d.cols), c = static_cast<int>(i % d.cols);
  if (!(activation[i] > 0.0f)) d.data[std::int64_t(r) * d.ld + c] = 0.0f;
}

__global__ void gather_add_kernel(DeviceMatrix src, DeviceIndex index, DeviceMatrix out) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= std::int64_t(index.count) * out.cols) return;
  const int e = static_cast<int>(i / out.cols), c = static_cast<int>(i % out.cols);
  const int from = index.data[std::int64_t(e) * index.stride + index.offset];
  out.data[std::int64_t(e) * out.ld + c] += src.data[std::int64_t(from) * src.ld + c];
}

__global__ void segment_sum_kernel(DeviceMatrix src, DeviceSegments segments, DeviceMatrix out,
                                   bool accumulate) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= std::int64_t(segments.nodes) * out.cols) return;
  const int node = static_cast<int>(i / out.cols), c = static_cast<int>(i % out.cols);
  float sum = 0.0f;
  for (int k = segments.offsets[node]; k < segments.offsets[node + 1]; ++k) {
    sum += src.data[std::int64_t(segments.rows[k]) * src.ld + c];
  }
  float& target = out.data[std::int64_t(node) * out.ld + c];
  target = accumulate ? target + sum : sum;
}

__global__ void add_kernel(const float* x, float* y, std::int64_t n) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i < n) y[i] += x[i];
}

__global__ void fill_kernel(DeviceMatrix m, float value) {
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= std::int64_t(m.rows) * m.cols) return;
  const int r = static_cast<int>(i / m.cols), c = static_cast<int>(i % m.cols);
  m.data[std::int64_t(r) * m.ld + c] = value;
}

std::int64_t size_of(const DeviceMatrix& m) {
  return std::int64_t(m.rows) * m.cols;
}

}  // namespace

void normalize(const float* in, const float* mean, const float* inv_std, int rows, int cols,
               float* out, cudaStream_t stream) {
  const std::int64_t n = std::int64_t(rows) * cols;
  if (n == 0) return;
  normalize_kernel<<<blocks_for(n), kThreads, 0, stream>>>(in, mean, inv_std, rows, cols, out);
}

void bias_relu(DeviceMatrix src, const float* bias, DeviceMatrix dst, cudaStream_t stream) {
  if (size_of(src) == 0) return;
  bias_relu_kernel<<<blocks_for(size_of(src)), kThreads, 0, stream>>>(src, bias, dst);
}

void add_bias(DeviceMatrix m, const float* bias, cudaStream_t stream) {
  if (size_of(m) == 0) return;
  add_bias_kernel<<<blocks_for(size_of(m)), kThreads, 0, stream>>>(m, bias);
}

void layer_norm_forward(DeviceMatrix m, const float* scale, const float* offset, float epsilon,
                        float* normalized, float* inv_std, cudaStream_t stream) {
  if (m.rows == 0) return;
  const int warps = kThreads / 32;
  layer_norm_forward_kernel<<<(m.rows + warps - 1) / warps, kThreads, 0, stream>>>(
      m, scale, offset, epsilon, normalized, inv_std);
}

void layer_norm_backward(DeviceMatrix d_out, const float* normalized, const float* inv_std,
                         const float* scale, float* d_pre, float* product, cudaStream_t stream) {
  if (d_out.rows == 0) return;
  const int warps = kThreads / 32;
  layer_norm_backward_kernel<<<(d_out.rows + warps - 1) / warps, kThreads, 0, stream>>>(
      d_out, normalized, inv_std, scale, d_pre, product);
}

void relu_mask(DeviceMatrix d, const float* activation, cudaStream_t stream) {
  if (size_of(d) == 0) return;
  relu_mask_kernel<<<blocks_for(size_of(d)), kThreads, 0, stream>>>(d, activation);
}

void gather_add(DeviceMatrix src, DeviceIndex index, DeviceMatrix out, cudaStream_t stream) {
  const std::int64_t n = std::int64_t(index.count) * out.cols;
  if (n == 0) return;
  gather_add_kernel<<<blocks_for(n), kThreads, 0, stream>>>(src, index, out);
}

void segment_sum(DeviceMatrix src, DeviceSegments segments, DeviceMatrix out, bool accumulate,
                 cudaStream_t stream) {
  const std::int64_t n = std::int64_t(segments.nodes) * out.cols;
  if (n == 0) return;
  segment_sum_kernel<<<blocks_for(n), kThreads, 0, stream>>>(src, segments, out, accumulate);
}

void add(const float* x, float* y, std::int64_t n, cudaStream_t stream) {
  if (n == 0) return;
  add_kernel<<<blocks_for(n), kThreads, 0, stream>>>(x, y, n);
}

void fill(DeviceMatrix m, float value, cudaStream_t stream) {
  if (size_of(m) == 0) return;
  fill_kernel<<<blocks_for(size_of(m)), kThreads, 0, stream>>>(m, value);
}

}  // namespace fignet::cuda
