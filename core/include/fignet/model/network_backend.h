// Where a Network's forward and backward passes run. The CPU backend is Network itself with its
// workspace; the CUDA backend (cuda/, FIGNET_WITH_CUDA) runs the same computation on a GPU with a
// device workspace. Callers (the trainer, predictors) hold one backend per thread and never see
// where the work was done: inputs and outputs are host memory.
#pragma once

#include <memory>
#include <string>

#include "fignet/model/network.h"

namespace fignet {

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
  // Backends that keep their own copy of the parameters re-read them after this call (the
  // parameters a backend was last given are otherwise assumed unchanged at the same address).
  virtual void parameters_changed() {}
  // Where the time of the calls so far went, for backends that measure it ("" otherwise).
  virtual std::string profile() const { return {}; }
};

// Network::forward and backward with a workspace of their own; `network` must outlive it.
std::unique_ptr<NetworkBackend> make_cpu_backend(const Network& network);

}  // namespace fignet
