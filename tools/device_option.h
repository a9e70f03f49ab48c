// `--device cpu|cuda[:N]`, `--tf32` and `--bf16` of the commands that run a network, in one place.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <string>

#include "fignet/model/network_backend.h"

namespace fignet::cli {

struct DeviceArgs {
  std::string device = "cpu";
  bool tf32 = false;
  bool bf16 = false;
};

// Registers --device, --tf32 and --bf16 on `cmd`.
void add_device_options(CLI::App& cmd, DeviceArgs& args);
// The backend --device names for `network`: nullptr for the CPU (callers keep their own path),
// whose products it sets to bf16 with --bf16 (process-wide: set_gemm_precision). Throws
// ConfigError for an unknown device, or one or a precision this build or machine cannot use.
std::unique_ptr<NetworkBackend> make_backend(const DeviceArgs& args, const Network& network);

// `--bf16` alone, for the commands that run a model on the CPU only (eval, compare): registers it
// on `cmd`, and with `bf16` set makes the process's products bf16, or throws ConfigError saying
// why this build or machine cannot.
void add_bf16_option(CLI::App& cmd, bool& bf16);
void use_bf16_products(bool bf16);

}  // namespace fignet::cli
