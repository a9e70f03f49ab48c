// Runs a third-party parser in a forked child process, so that its crashes, runaway allocations
// and endless loops on hostile files become errors instead of taking the caller down. Debian's
// assimp 5.2 keeps allocating on its own invalid test model OutOfMemory.off (a face count of
// 3.5e11) until the machine runs out; no input file may take a FIGNet program down.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace fignet::bullet {

struct IsolationLimits {
  std::size_t extra_memory_bytes = std::size_t{4} << 30;  // address space beyond the parent's
  unsigned seconds = 120;                                 // wall-clock limit (SIGALRM)
};

// Runs `work` in a child process and returns the bytes it produced. `work` reports a normal
// failure by throwing; its message comes back in a std::runtime_error. A crash, the memory limit
// or the time limit also throw std::runtime_error, saying which.
std::string run_isolated(const std::function<std::string()>& work,
                         const IsolationLimits& limits = {});

}  // namespace fignet::bullet
