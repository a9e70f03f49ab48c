#include "fignet/nn/mlp.h"

#include <cmath>
#include <numeric>

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

void Mlp::forward(const float* params, MatrixView first, MlpCache& cache, MatrixRef out) const {
  const Eigen::Index n = first.rows();
  auto bias = [&](size_t offset, int size) { return tensor(params, offset, 1, size).row(0); };
  // Hidden layers: ReLU(x·W + b).
  MatrixView h1 = cache.hidden1.view(n, hidden_);
  h1 = (first.rowwise() + bias(b0_, hidden_)).cwiseMax(0.0f);
  MatrixView h2 = cache.hidden2.view(n, hidden_);
  h2.noalias() = h1 * tensor(params, w1_, hidden_, hidden_);
  h2 = (h2.rowwise() + bias(b1_, hidden_)).cwiseMax(0.0f);
  out.noalias() = h2 * tensor(params, w2_, hidden_, output_);
  out.rowwise() += bias(b2_, output_);
  if (!layer_norm_) return;
  // LayerNorm over each row: x̂ = (y − μ)/sqrt(σ² + ε), out = scale·x̂ + offset.
  MatrixView normalized = cache.normalized.view(n, output_);
  MatrixView inv_std = cache.inv_std.view(n, 1);
  for (Eigen::Index r = 0; r < n; ++r) {
    const float mean = out.row(r).mean();
    normalized.row(r) = out.row(r).array() - mean;
    const float variance = normalized.row(r).squaredNorm() / static_cast<float>(output_);
    inv_std(r, 0) = 1.0f / std::sqrt(variance + kLayerNormEpsilon);
    normalized.row(r) *= inv_std(r, 0);
  }
  out = (normalized.array().rowwise() * bias(scale_, output_).array()).matrix();
  out.rowwise() += bias(offset_, output_);
}

void Mlp::backward(const float* params, float* grads, const ConstMatrixRef& d_out,
                   MlpCache& cache) const {
  const Eigen::Index n = d_out.rows();
  auto grad_row = [&](size_t offset, int size) { return tensor(grads, offset, 1, size).row(0); };
  // Through LayerNorm: dx = inv_std·(dx̂ − mean(dx̂) − x̂·mean(dx̂·x̂)), dx̂ = d_out·scale.
  MatrixView d_pre = cache.d_pre_norm.view(n, output_);
  if (layer_norm_) {
    const ConstMatrixView normalized = cache.normalized.cget();
    const ConstMatrixView inv_std = cache.inv_std.cget();
    grad_row(scale_, output_) += (d_out.array() * normalized.array()).colwise().sum().matrix();
    grad_row(offset_, output_) += d_out.colwise().sum();
    const auto scale = tensor(params, scale_, 1, output_).row(0).array();
    // d_pre first holds dx̂ = d_out·scale, then is turned into dx row by row in place.
    d_pre = (d_out.array().rowwise() * scale).matrix();
    for (Eigen::Index r = 0; r < n; ++r) {
      const float mean_d = d_pre.row(r).mean();
      const float mean_dx = d_pre.row(r).dot(normalized.row(r)) / static_cast<float>(output_);
      d_pre.row(r) = inv_std(r, 0) *
                     (d_pre.row(r).array() - mean_d - normalized.row(r).array() * mean_dx).matrix();
    }
  } else {
    d_pre = d_out;
  }
  // Output layer.
  const ConstMatrixView h1 = cache.hidden1.cget(), h2 = cache.hidden2.cget();
  tensor(grads, w2_, hidden_, output_).noalias() += h2.transpose() * d_pre;
  grad_row(b2_, output_) += d_pre.colwise().sum();
  MatrixView d_h2 = cache.d_hidden.view(n, hidden_);
  d_h2.noalias() = d_pre * tensor(params, w2_, hidden_, output_).transpose();
  d_h2.array() *= (h2.array() > 0.0f).cast<float>();  // ReLU passes gradient where active
  // Second hidden layer.
  tensor(grads, w1_, hidden_, hidden_).noalias() += h1.transpose() * d_h2;
  grad_row(b1_, hidden_) += d_h2.colwise().sum();
  MatrixView d_first = cache.d_first.view(n, hidden_);
  d_first.noalias() = d_h2 * tensor(params, w1_, hidden_, hidden_).transpose();
  d_first.array() *= (h1.array() > 0.0f).cast<float>();
  grad_row(b0_, hidden_) += d_first.colwise().sum();
}

void Mlp::forward_dense(const float* params, const ConstMatrixRef& x, Buffer& first,
                        MlpCache& cache, MatrixRef out) const {
  MatrixView z = first.view(x.rows(), hidden_);
  z.noalias() = x * tensor(params, w0_, input_, hidden_);
  forward(params, z, cache, out);
}

void Mlp::backward_dense(const float* params, float* grads, const ConstMatrixRef& x,
                         const ConstMatrixRef& d_out, MlpCache& cache, MatrixRef* dx) const {
  backward(params, grads, d_out, cache);
  MatrixView dw0 = tensor(grads, w0_, input_, hidden_);
  backprop_product(x, tensor(params, w0_, input_, hidden_), cache.d_first.get(), dw0, dx);
}

}  // namespace fignet
