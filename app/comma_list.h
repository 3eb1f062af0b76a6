#pragma once
// A flag's comma-separated list ("R,TT,TRT", "beta_long,eta") as its items;
// empty items are skipped.
#include <sstream>
#include <string>
#include <vector>

namespace fiberlab::app {

inline std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, ','))
    if (!part.empty()) out.push_back(part);
  return out;
}

}  // namespace fiberlab::app
