#pragma once
// What a command the robustness tests start left behind: its exit status and
// what it printed, and a file's whole text.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fiberlab::robustness {

struct Outcome {
  int status;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace fiberlab::robustness
