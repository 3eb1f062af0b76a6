#pragma once
// A step every rank of an MPI run takes together: when it fails on any rank,
// every rank stops, rank 0 with the first failing rank's message and the
// others quietly (sim::FailedElsewhere), so that a bad config or a full disk
// on one rank cannot leave the others waiting in a collective call.
#include <new>
#include <optional>
#include <string>

#include "common/error.h"
#include "sim/run/process_group.h"

namespace fiberlab::app {

template <typename Step>
void on_all_ranks(const sim::ProcessGroup& group, Step&& step) {
  std::optional<std::string> error;
  try {
    step();
  } catch (const Error& e) {
    error = e.what();
  } catch (const std::bad_alloc&) {
    error = "out of memory";
  } catch (const std::exception& e) {
    error = std::string("internal error: ") + e.what();
  }
  if (const auto message = group.agree_on_error(error)) {
    if (!group.is_root()) throw sim::FailedElsewhere{};
    throw Error(*message);
  }
}

}  // namespace fiberlab::app
