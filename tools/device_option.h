// `--device cpu|cuda[:N]` and `--tf32` of the commands that run a network, in one place.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <string>

#include "fignet/model/network_backend.h"

namespace fignet::cli {

struct DeviceArgs {
  std::string device = "cpu";
  bool tf32 = false;
};

// Registers --device and --tf32 on `cmd`.
void add_device_options(CLI::App& cmd, DeviceArgs& args);
// The backend --device names for `network`: nullptr for the CPU (callers keep their own path).
// Throws ConfigError for an unknown device or one this build or machine cannot use.
std::unique_ptr<NetworkBackend> make_backend(const DeviceArgs& args, const Network& network);

}  // namespace fignet::cli
