#include "app/merge.h"

#include "common/atomic_output.h"

namespace fiberlab::app {

sim::MergeSummary merge(const std::vector<std::string>& inputs, const std::string& output) {
  check_output_target(output, inputs);  // before reading
  return sim::merge_result_files(inputs, output);
}

}  // namespace fiberlab::app
