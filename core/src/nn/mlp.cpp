#include "fignet/nn/mlp.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "fignet/nn/gemm.h"
#include "fignet/nn/ops.h"

namespace fignet {

Mlp::Mlp(ParameterLayout& layout, const std::string& name, std::vector<int> input_blocks,
         int hidden, int output, bool layer_norm)
    : block_sizes_(std::move(input_blocks)),
      input_(std::accumulate(block_sizes_.begin(), block_sizes_.end(), 0)),
      hidden_(hidden),
      output_(output),
      layer_norm_(layer_norm) {
  int offset = 0;
  for (int size : block_sizes_) block_offsets_.push_back(offset), offset += size;
  w0_ = layout.add(name + "/linear_0/w", input_, hidden, Init::kFanIn);
  b0_ = layout.add(name + "/linear_0/b", 1, hidden, Init::kZeros);
  w1_ = layout.add(name + "/linear_1/w", hidden, hidden, Init::kFanIn);
  b1_ = layout.add(name + "/linear_1/b", 1, hidden, Init::kZeros);
  w2_ = layout.add(name + "/linear_2/w", hidden, output, Init::kFanIn);
  b2_ = layout.add(name + "/linear_2/b", 1, output, Init::kZeros);
  if (layer_norm_) {
    scale_ = layout.add(name + "/layer_norm/scale", 1, output, Init::kOnes);
    offset_ = layout.add(name + "/layer_norm/offset", 1, output, Init::kZeros);
  }
}

ConstMatrixView Mlp::first_weight(const float* params, int k) const {
  return {params + w0_ + static_cast<size_t>(block_offsets_[k]) * hidden_, block_sizes_[k],
          hidden_};
}

MatrixView Mlp::first_weight(float* params, int k) const {
  return {params + w0_ + static_cast<size_t>(block_offsets_[k]) * hidden_, block_sizes_[k],
          hidden_};
}

namespace {

// The elementwise passes below walk each row once while it is in L1, with plain loops over
// contiguous columns that the compiler vectorises. `omp simd reduction` lets the row sums
// vectorise too: without it the compiler keeps their order and adds one float at a time.

// d *= (activation > 0), and db += Σ_rows d: the adjoint of a bias and ReLU.
void relu_backward(MatrixRef d, const ConstMatrixRef& activation, float* db) {
  const Eigen::Index cols = d.cols();
  for (Eigen::Index r = 0; r < d.rows(); ++r) {
    float* row = d.row(r).data();
    const float* a = activation.row(r).data();
    for (Eigen::Index c = 0; c < cols; ++c) {
      row[c] = a[c] > 0.0f ? row[c] : 0.0f;
      db[c] += row[c];
    }
  }
}

// The first layer's bias and ReLU on a block of rows, as the second layer's product reads them.
struct FirstActivation {
  MatrixView first, hidden1;
  const float* bias;

  static void run(const void* context, Eigen::Index first_row, Eigen::Index rows) {
    const auto& pass = *static_cast<const FirstActivation*>(context);
    MatrixView first = pass.first, hidden1 = pass.hidden1;
    bias_activation(first.middleRows(first_row, rows), pass.bias, Activation::kRelu,
                    hidden1.middleRows(first_row, rows));
  }
};

// LayerNorm over each row of a block of the output layer's product, as it leaves the product:
// x̂ = (y − μ)/sqrt(σ² + ε), out = scale·x̂ + offset; x̂ and 1/σ are kept for backward.
struct LayerNormRows {
  float* out;
  Eigen::Index out_stride;
  float* normalized;  // rows of `width`
  float* inv_std;
  int width;
  const float* scale;
  const float* offset;

  static void run(const void* context, Eigen::Index first_row, Eigen::Index rows) {
    const auto& pass = *static_cast<const LayerNormRows*>(context);
    const int width = pass.width;
    const float inv_width = 1.0f / static_cast<float>(width);
    const float* scale = pass.scale;
    const float* offset = pass.offset;
    for (Eigen::Index r = first_row; r < first_row + rows; ++r) {
      float* y = pass.out + r * pass.out_stride;
      float* x_hat = pass.normalized + r * width;
      float sum = 0.0f;
#pragma omp simd reduction(+ : sum)
      for (int c = 0; c < width; ++c) sum += y[c];
      const float mean = sum * inv_width;
      float squares = 0.0f;
#pragma omp simd reduction(+ : squares)
      for (int c = 0; c < width; ++c) {
        x_hat[c] = y[c] - mean;
        squares += x_hat[c] * x_hat[c];
      }
      const float inv = 1.0f / std::sqrt(squares * inv_width + Mlp::kLayerNormEpsilon);
      pass.inv_std[r] = inv;
      for (int c = 0; c < width; ++c) {
        x_hat[c] *= inv;
        y[c] = scale[c] * x_hat[c] + offset[c];
      }
    }
  }
};

}  // namespace

void Mlp::forward(const float* params, MatrixView first, MlpCache& cache, MatrixRef out) const {
  const Eigen::Index n = first.rows();
  // Hidden layers: ReLU(x·W + b). The first's bias and ReLU run on each block of rows just before
  // the second's product reads it; the second's inside its product.
  MatrixView h1 = cache.hidden1.view(n, hidden_);
  MatrixView h2 = cache.hidden2.view(n, hidden_);
  const FirstActivation first_activation{first, h1, params + b0_};
  gemm_bias(h1, tensor(params, w1_, hidden_, hidden_), Transpose::kNo, params + b1_,
            Activation::kRelu, h2, {&FirstActivation::run, &first_activation}, {});
  // Output layer: y = x·W2 + b2, then LayerNorm on each block of rows as it leaves the product.
  LayerNormRows layer_norm_rows{};
  RowPass layer_norm;
  if (layer_norm_) {
    layer_norm_rows = {out.data(),
                       out.outerStride(),
                       cache.normalized.view(n, output_).data(),
                       cache.inv_std.view(n, 1).data(),
                       output_,
                       params + scale_,
                       params + offset_};
    layer_norm = {&LayerNormRows::run, &layer_norm_rows};
  }
  gemm_bias(h2, tensor(params, w2_, hidden_, output_), Transpose::kNo, params + b2_,
            Activation::kNone, out, {}, layer_norm);
}

void Mlp::backward(const float* params, float* grads, const ConstMatrixRef& d_out,
                   MlpCache& cache) const {
  const Eigen::Index n = d_out.rows();
  // Through LayerNorm: dx = inv_std·(dx̂ − mean(dx̂) − x̂·mean(dx̂·x̂)), dx̂ = d_out·scale; the
  // output bias's gradient is Σ_rows dx.
  MatrixView d_pre = cache.d_pre_norm.view(n, output_);
  float* d_b2 = grads + b2_;
  if (layer_norm_) {
    const ConstMatrixView normalized = cache.normalized.cget();
    const ConstMatrixView inv_std = cache.inv_std.cget();
    const float* scale = params + scale_;
    float* d_scale = grads + scale_;
    float* d_offset = grads + offset_;
    const float inv_width = 1.0f / static_cast<float>(output_);
    for (Eigen::Index r = 0; r < n; ++r) {
      const float* g = d_out.row(r).data();
      const float* x_hat = normalized.row(r).data();
      float* dx = d_pre.row(r).data();
      float sum_d = 0.0f, sum_dx = 0.0f;
#pragma omp simd reduction(+ : sum_d, sum_dx)
      for (int c = 0; c < output_; ++c) {
        d_scale[c] += g[c] * x_hat[c];
        d_offset[c] += g[c];
        dx[c] = g[c] * scale[c];
        sum_d += dx[c];
        sum_dx += dx[c] * x_hat[c];
      }
      const float inv = inv_std(r, 0), mean_d = sum_d * inv_width, mean_dx = sum_dx * inv_width;
      for (int c = 0; c < output_; ++c) {
        dx[c] = inv * (dx[c] - mean_d - x_hat[c] * mean_dx);
        d_b2[c] += dx[c];
      }
    }
  } else {
    for (Eigen::Index r = 0; r < n; ++r) {
      const float* g = d_out.row(r).data();
      float* dx = d_pre.row(r).data();
      for (int c = 0; c < output_; ++c) d_b2[c] += (dx[c] = g[c]);
    }
  }
  // Output layer.
  const ConstMatrixView h1 = cache.hidden1.cget(), h2 = cache.hidden2.cget();
  gemm(h2, Transpose::kYes, d_pre, Transpose::kNo, tensor(grads, w2_, hidden_, output_), true);
  MatrixView d_h2 = cache.d_hidden.view(n, hidden_);
  gemm(d_pre, Transpose::kNo, tensor(params, w2_, hidden_, output_), Transpose::kYes, d_h2, false);
  relu_backward(d_h2, h2, grads + b1_);  // ReLU passes gradient where active
  // Second hidden layer.
  gemm(h1, Transpose::kYes, d_h2, Transpose::kNo, tensor(grads, w1_, hidden_, hidden_), true);
  MatrixView d_first = cache.d_first.view(n, hidden_);
  gemm(d_h2, Transpose::kNo, tensor(params, w1_, hidden_, hidden_), Transpose::kYes, d_first,
       false);
  relu_backward(d_first, h1, grads + b0_);
}

void Mlp::forward_dense(const float* params, const ConstMatrixRef& x, Buffer& first,
                        MlpCache& cache, MatrixRef out) const {
  MatrixView z = first.view(x.rows(), hidden_);
  gemm(x, Transpose::kNo, tensor(params, w0_, input_, hidden_), Transpose::kNo, z, false);
  forward(params, z, cache, out);
}

void Mlp::backward_dense(const float* params, float* grads, const ConstMatrixRef& x,
                         const ConstMatrixRef& d_out, MlpCache& cache, MatrixRef* dx) const {
  backward(params, grads, d_out, cache);
  MatrixView dw0 = tensor(grads, w0_, input_, hidden_);
  backprop_product(x, tensor(params, w0_, input_, hidden_), cache.d_first.get(), dw0, dx);
}

}  // namespace fignet
