#pragma once
// The message of the fiberlab::Error a call throws ("" when it throws none):
// tests check that a refusal names the field and what is allowed.
#include <functional>
#include <string>

#include "common/error.h"

namespace fiberlab {

inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace fiberlab
