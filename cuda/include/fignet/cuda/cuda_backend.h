// The CUDA backend (FIGNET_WITH_CUDA): the network's forward and backward passes on an NVIDIA GPU,
// cuBLAS for the products and own kernels for gathers, segment sums, LayerNorm and activations.
// Same parameters, normalisers and graphs as the CPU path; results agree with it to float
// tolerance (tests/cuda). Segment sums are ordered, not atomic, so a run is deterministic.
#pragma once

#include <memory>
#include <string>

#include "fignet/error.h"
#include "fignet/model/network_backend.h"

namespace fignet::cuda {

// A CUDA call that failed: no driver, no device, out of memory. The message names the call.
class DeviceError : public Error {
 public:
  using Error::Error;
};

struct CudaOptions {
  int device = 0;
  // TensorFloat-32 in cuBLAS's products: faster on Ampere and later, ~1e-3 relative error.
  bool tf32 = false;
};

// GPUs this process can use: 0 without a driver or device (never throws).
int device_count();
// "NVIDIA H100 80GB HBM3 (sm_90, 79.1 GiB)"; throws DeviceError for a device that is not there.
std::string describe_device(int device);

// A backend on `options.device`; `network` must outlive it. Throws DeviceError when the device
// cannot be used.
std::unique_ptr<NetworkBackend> make_cuda_backend(const Network& network,
                                                  const CudaOptions& options = {});

}  // namespace fignet::cuda
