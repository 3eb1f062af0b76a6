#pragma once
// fiberlab reports bad input as an Error whose message is one line that a user
// can act on (the file, the field, the value, the allowed range).
#include <stdexcept>
#include <string>

namespace fiberlab {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace fiberlab
