// libFuzzer harness: arbitrary bytes as a trajectory file. Reading may fail only with a
// fignet::Error (FileError naming the file); anything else, or a crash, is a finding.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "fignet/error.h"
#include "fignet/io/trajectory_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path =
      "/tmp/fignet_fuzz_trajectory_" + std::to_string(::getpid()) + ".h5";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    for (const fignet::Trajectory& t : fignet::read_trajectories(path)) t.validate();
  } catch (const fignet::Error&) {
  }
  return 0;
}
