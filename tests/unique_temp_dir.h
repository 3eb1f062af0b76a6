#pragma once
// A new, empty folder under the system's temporary folder whose name no other
// process can get (mkdtemp: PREFIX_XXXXXX), so that test runs in parallel (two
// checkouts' ctest, or two test programs) never share or delete each other's
// files. The caller removes it.
#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace fiberlab::test_support {

inline std::filesystem::path unique_temp_dir(const std::string& prefix) {
  std::string name = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
  if (mkdtemp(name.data()) == nullptr)
    throw std::runtime_error("cannot create a temporary folder " + name);
  return name;
}

}  // namespace fiberlab::test_support
