#pragma once
// The one exception type for bad outside input (files, sockets, command lines): it always says
// where (file and line when known) and what, so a user can find and fix the input.

#include <stdexcept>
#include <string>

namespace mocap {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& where, const std::string& what)
      : std::runtime_error(where.empty() ? what : where + ": " + what) {}
  InputError(const std::string& file, long line, const std::string& what)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + what) {}
};

}  // namespace mocap
