#include "fignet/model/network_backend.h"

namespace fignet {

namespace {

class CpuBackend final : public NetworkBackend {
 public:
  explicit CpuBackend(const Network& network) : network_(network) {}
  std::string name() const override { return "cpu"; }
  ConstMatrixView forward(const float* params, const Normalizers& normalizers, const Graph& graph,
                          bool keep_for_backward) override {
    return network_.forward(params, normalizers, graph, workspace_, keep_for_backward);
  }
  void backward(const float* params, float* grads, const Graph& graph,
                const ConstMatrixRef& d_output) override {
    network_.backward(params, grads, graph, d_output, workspace_);
  }

 private:
  const Network& network_;
  NetworkWorkspace workspace_;
};

}  // namespace

std::unique_ptr<NetworkBackend> make_cpu_backend(const Network& network) {
  return std::make_unique<CpuBackend>(network);
}

}  // namespace fignet
