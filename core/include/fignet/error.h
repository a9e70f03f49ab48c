// Exceptions thrown by fignet. Every message names what was wrong, where, and the offending value,
// so a tool can print it as one line and exit non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace fignet {

// Base of every error the library throws on bad input or API misuse.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A mesh that cannot be used: non-finite vertex, index out of range, no faces, degenerate face.
class MeshError : public Error {
 public:
  using Error::Error;
};

// A configuration or scene that is inconsistent: bad parameter value, wrong history length.
class ConfigError : public Error {
 public:
  using Error::Error;
};

// A file that cannot be read or written: missing, truncated, foreign, wrong version or schema.
class FileError : public Error {
 public:
  using Error::Error;
};

}  // namespace fignet
