// The processes a `fignet` command runs in: one, or every process of an MPI launch (mpirun,
// srun). Process 0 alone prints, logs and writes files.
#pragma once

#include "fignet/train/collective.h"

namespace fignet::cli {

struct ProcessGroup {
  Collective* collective = nullptr;  // never null once main has set it up
  int rank() const { return collective->rank(); }
  int size() const { return collective->size(); }
  bool is_root() const { return rank() == 0; }
  // Every `size()`-th trajectory from the `rank()`-th: this process's share.
  template <class T>
  std::vector<T> share_of(std::vector<T> all) const {
    std::vector<T> mine;
    for (size_t i = static_cast<size_t>(rank()); i < all.size(); i += static_cast<size_t>(size())) {
      mine.push_back(std::move(all[i]));
    }
    return mine;
  }
};

// Set up by main() before any command runs.
ProcessGroup& process_group();

}  // namespace fignet::cli
