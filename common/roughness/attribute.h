#pragma once
// A roughness model's parameters as the attributes of a result file's
// /roughness group (docs/FILE_FORMAT.md), named and valued by the model.
#include <string>
#include <variant>
#include <vector>

namespace fiberlab::roughness {

struct Attribute {
  std::string name;
  std::variant<std::vector<double>, std::string> value;
};

}  // namespace fiberlab::roughness
