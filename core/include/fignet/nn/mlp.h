// The MLP of the seed (C.2): Linear–ReLU–Linear–ReLU–Linear, followed by LayerNorm except in the
// decoder. Its first layer's input is a concatenation of blocks; callers form the first product
// block by block (see ops.h) and the MLP takes it from there.
#pragma once

#include <string>
#include <vector>

#include "fignet/nn/buffer.h"
#include "fignet/nn/parameters.h"

namespace fignet {

// What forward() keeps for backward(), reused across steps.
struct MlpCache {
  Buffer hidden1, hidden2;      // post-ReLU activations
  Buffer normalized, inv_std;   // LayerNorm's x̂ and 1/σ per row
  Buffer d_hidden, d_pre_norm;  // scratch for backward
  Buffer d_first;               // backward's result: d(first-layer product), rows x hidden
};

// Where an MLP's tensors start in the flat parameter array (offsets in floats).
struct MlpTensors {
  size_t w0 = 0, b0 = 0, w1 = 0, b1 = 0, w2 = 0, b2 = 0, scale = 0, offset = 0;
};

class Mlp {
 public:
  static constexpr float kLayerNormEpsilon = 1e-5f;

  Mlp() = default;
  // Registers the MLP's tensors as "<name>/linear_{0,1,2}/{w,b}" and "<name>/layer_norm/{scale,
  // offset}". `input_blocks` are the widths of the concatenated inputs.
  Mlp(ParameterLayout& layout, const std::string& name, std::vector<int> input_blocks, int hidden,
      int output, bool layer_norm);

  int hidden() const { return hidden_; }
  int output() const { return output_; }
  int num_blocks() const { return static_cast<int>(block_sizes_.size()); }
  int input() const { return input_; }
  bool layer_norm() const { return layer_norm_; }
  // For other backends, which run the same computation on their own copy of the parameters.
  MlpTensors tensors() const { return {w0_, b0_, w1_, b1_, w2_, b2_, scale_, offset_}; }

  // Rows of the first weight that multiply input block k.
  ConstMatrixView first_weight(const float* params, int k) const;
  MatrixView first_weight(float* params, int k) const;

  // out = MLP(input) given first = Σ_k input_k·W0_k (no bias yet; overwritten as scratch).
  void forward(const float* params, MatrixView first, MlpCache& cache, MatrixRef out) const;
  // Accumulates the gradients of every tensor but W0 into `grads` and leaves d(first) in
  // cache.d_first, from which callers backpropagate into W0's blocks and the inputs.
  void backward(const float* params, float* grads, const ConstMatrixRef& d_out,
                MlpCache& cache) const;

  // Single-input convenience: out = MLP(x).
  void forward_dense(const float* params, const ConstMatrixRef& x, Buffer& first, MlpCache& cache,
                     MatrixRef out) const;
  // ... and its adjoint, accumulating into dx when given.
  void backward_dense(const float* params, float* grads, const ConstMatrixRef& x,
                      const ConstMatrixRef& d_out, MlpCache& cache, MatrixRef* dx) const;

 private:
  std::vector<int> block_sizes_, block_offsets_;
  int input_ = 0, hidden_ = 0, output_ = 0;
  bool layer_norm_ = false;
  size_t w0_ = 0, b0_ = 0, w1_ = 0, b1_ = 0, w2_ = 0, b2_ = 0, scale_ = 0, offset_ = 0;
};

}  // namespace fignet
