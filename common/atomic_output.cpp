#include "common/atomic_output.h"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "common/error.h"

namespace fiberlab {

namespace fs = std::filesystem;

AtomicOutput::AtomicOutput(std::string target) : target_(std::move(target)) {
  if (target_.empty()) throw Error("output: the output path is empty");
  const fs::path p(target_);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(fmt::format("output: {}: folder {} does not exist", target_, dir.string()));
  if (fs::is_directory(p, ec))
    throw Error(fmt::format("output: {}: is a folder, not a file path", target_));
  if (access(dir.c_str(), W_OK) != 0)
    throw Error(fmt::format("output: {}: folder {} is not writable", target_, dir.string()));
  temp_ = (dir / fmt::format(".{}.tmp-{}", p.filename().string(), getpid())).string();
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicOutput::commit() {
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) throw Error(fmt::format("output: {}: cannot rename the finished file: {}", target_,
                                  ec.message()));
  committed_ = true;
}

}  // namespace fiberlab
