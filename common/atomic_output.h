#pragma once
// A result file is written completely or not at all (SPEC section 9): write
// to a temporary name in the same folder, then rename over the target.
#include <string>

namespace fiberlab {

class AtomicOutput {
 public:
  // Checks that the target's folder exists and is writable; throws
  // fiberlab::Error naming the path otherwise.
  explicit AtomicOutput(std::string target);
  ~AtomicOutput();  // removes the temporary file unless commit() ran
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& target() const { return target_; }
  void commit();  // rename temp -> target

 private:
  std::string target_, temp_;
  bool committed_ = false;
};

}  // namespace fiberlab
