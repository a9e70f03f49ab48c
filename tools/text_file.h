// Text outputs of the tools (JSON results, HTML reports), written to a temporary file beside the
// destination and renamed into place, so a reader never sees half a file.
#pragma once

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string_view>

#include "fignet/error.h"

namespace fignet::cli {

inline void write_text_atomically(const std::filesystem::path& path, std::string_view text) {
  const std::filesystem::path temporary =
      path.string() + fmt::format(".tmp{}", static_cast<long>(::getpid()));
  {
    std::ofstream out(temporary, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw FileError(fmt::format("'{}': cannot write", path.string()));
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    throw FileError(fmt::format("'{}': cannot write ({})", path.string(), error.message()));
  }
}

}  // namespace fignet::cli
