// The message of the exception a call throws, for tests that check what an error says.
#pragma once

#include <functional>
#include <string>

#include "fignet/error.h"

namespace fignet::testing {

// What the `E` (a fignet::Error by default) thrown by `f` says; "no error" when `f` throws none.
// Other exceptions pass through and fail the test.
template <class E = Error>
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace fignet::testing
