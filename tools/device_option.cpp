#include "device_option.h"

#include <fmt/format.h>

#include <charconv>

#include "fignet/error.h"
#include "fignet/nn/gemm.h"
#ifdef FIGNET_WITH_CUDA
#include "fignet/cuda/cuda_backend.h"
#endif

namespace fignet::cli {

void add_device_options(CLI::App& cmd, DeviceArgs& args) {
  cmd.add_option("--device", args.device,
                 "Where the network runs: cpu, or cuda / cuda:N (an NVIDIA GPU; builds with "
                 "FIGNET_WITH_CUDA, see docs/gpu.md)")
      ->capture_default_str();
  cmd.add_flag("--tf32", args.tf32,
               "With --device cuda: TensorFloat-32 matrix products (faster, ~1e-3 relative "
               "error in each product)");
  cmd.add_flag("--bf16", args.bf16,
               "With --device cpu: bfloat16 matrix products (oneDNN on processors with "
               "AVX512-BF16 or AMX: products ~1.4x, a training step 1.06-1.3x as fast; each "
               "operand rounded to 8 significant bits, sums in f32; see docs/network.md)");
}

void add_bf16_option(CLI::App& cmd, bool& bf16) {
  cmd.add_flag("--bf16", bf16,
               "bfloat16 matrix products (oneDNN on processors with AVX512-BF16 or AMX; each "
               "operand rounded to 8 significant bits, sums in f32; see docs/network.md)");
}

void use_bf16_products(bool bf16) {
  if (!bf16) return;
  const std::string why_not = gemm_precision_unavailable(GemmPrecision::kBf16);
  if (!why_not.empty()) throw ConfigError("--bf16: " + why_not + "; leave --bf16 out");
  set_gemm_precision(GemmPrecision::kBf16);
}

std::unique_ptr<NetworkBackend> make_backend(const DeviceArgs& args, const Network& network) {
  if (args.device == "cpu") {
    if (args.tf32) throw ConfigError("--tf32 applies to --device cuda only");
    use_bf16_products(args.bf16);
    return nullptr;
  }
  if (args.bf16) {
    throw ConfigError(
        fmt::format("--bf16 applies to --device cpu only (on {}: --tf32)", args.device));
  }
  int index = 0;
  if (args.device != "cuda") {
    const std::string prefix = "cuda:";
    const char* first = args.device.data() + prefix.size();
    const char* last = args.device.data() + args.device.size();
    if (args.device.rfind(prefix, 0) != 0 || std::from_chars(first, last, index).ptr != last ||
        first == last || index < 0) {
      throw ConfigError(
          fmt::format("--device '{}': expected cpu, cuda or cuda:N (N a GPU index)", args.device));
    }
  }
#ifdef FIGNET_WITH_CUDA
  if (cuda::device_count() == 0) {
    throw ConfigError(
        fmt::format("--device {}: no CUDA GPU is visible to this process (driver "
                    "missing, or CUDA_VISIBLE_DEVICES hides them)",
                    args.device));
  }
  return cuda::make_cuda_backend(network, {index, args.tf32});
#else
  (void)network;
  throw ConfigError(
      fmt::format("--device {}: this fignet was built without the CUDA backend "
                  "(configure with --preset cuda on a machine with nvcc; "
                  "docs/gpu.md)",
                  args.device));
#endif
}

}  // namespace fignet::cli
