#pragma once
// The message of the error that a call throws, for tests of what a user reads.

#include <string>
#include <utility>

#include "core/input_error.hpp"

namespace mocap::test {

// What `action` throws as an `Error` (InputError: bad input, named); "" when it throws nothing, so
// that looking for the expected words in it fails and shows that no error came.
template <class Error = InputError, class Action>
std::string error_of(Action&& action) {
  try {
    std::forward<Action>(action)();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace mocap::test
