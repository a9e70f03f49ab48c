// Where a Network's forward and backward passes run. The CPU backend is Network itself with its
// workspace; the CUDA backend (cuda/, FIGNET_WITH_CUDA) runs the same computation on a GPU with a
// device workspace. Callers (the trainer, predictors) hold one backend per thread and never see
// where the work was done: inputs and outputs are host memory.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "fignet/model/network.h"

namespace fignet {

// The loss over the network's output for mesh nodes [first_node, first_node + output.rows()):
// writes d(loss)/d(output) for those rows into d_output and returns their part of the loss.
// Called once per chunk of the graph, possibly from several threads at once (for disjoint
// rows), so it must only read shared state.
using LossGradient =
    std::function<double(int first_node, const ConstMatrixRef& output, MatrixRef d_output)>;

class NetworkBackend {
 public:
  virtual ~NetworkBackend() = default;
  // "cpu", or the device and its settings ("cuda:0 NVIDIA H100 80GB HBM3, tf32 off").
  virtual std::string name() const = 0;
  // As Network::forward; the output is host memory, valid until the next call.
  virtual ConstMatrixView forward(const float* params, const Normalizers& normalizers,
                                  const Graph& graph, bool keep_for_backward) = 0;
  // As Network::backward: accumulates d(loss)/d(params) into the host array `grads`.
  virtual void backward(const float* params, float* grads, const Graph& graph,
                        const ConstMatrixRef& d_output) = 0;
  // One training pass: forward, the loss's gradient from `loss`, backward. Accumulates
  // d(loss)/d(params) into `grads` and returns the loss (the sum of `loss`'s returns, in node
  // order). The default runs forward() over the whole graph, then backward(); the CPU backend
  // runs a batch as chunks of whole scenes, forward and backward one chunk after another, so
  // that only a few chunks' activations exist at once.
  virtual double forward_backward(const float* params, const Normalizers& normalizers,
                                  const Graph& graph, float* grads, const LossGradient& loss);
  // Backends that keep their own copy of the parameters re-read them after this call (the
  // parameters a backend was last given are otherwise assumed unchanged at the same address).
  virtual void parameters_changed() {}
  // Where the time of the calls so far went, for backends that measure it ("" otherwise).
  virtual std::string profile() const { return {}; }

 private:
  Buffer d_output_;  // forward_backward's default: d(loss)/d(output) of the whole graph
};

// Network::forward and backward with a workspace of their own; `network` must outlive it.
std::unique_ptr<NetworkBackend> make_cpu_backend(const Network& network);

}  // namespace fignet
