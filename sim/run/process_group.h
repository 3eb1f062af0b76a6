#pragma once
// The processes of one run: the MPI ranks when fiberlab was started by an MPI
// launcher (mpirun, srun) and built with MPI (FIBERLAB_MPI), otherwise just
// this process. Only the calls a run needs: a few flags agreed by every rank,
// exact sums of 128-bit tallies into rank 0 and one error message for all.
// Only the calling (main) thread talks to MPI (MPI_THREAD_FUNNELED), through
// fiberlab's MPI module (sim/run/mpi_calls.h), loaded only when launched so.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sim/store/exact_tally.h"

extern "C" struct FiberlabMpiCalls;

namespace fiberlab::sim {

class ProcessGroup {
 public:
  // Starts MPI when launched by an MPI launcher; finalizes it on destruction.
  // Throws fiberlab::Error when launched as several processes by a build
  // without MPI (each would run the whole job and write the same file), or
  // when the MPI module cannot be loaded.
  ProcessGroup();
  ~ProcessGroup();
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;

  static const ProcessGroup& single();  // this process alone, no MPI

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }

  // Element-wise maximum over the ranks, on every rank.
  void max(std::vector<std::int64_t>& v) const;
  // Element-wise exact sum over the ranks into rank 0's `v` (other ranks' `v`
  // is left unspecified).
  void sum_to_root(std::vector<ExactTally::Word>& v) const;
  // When any rank passes a message, every rank gets the message of the lowest
  // such rank; nullopt when none failed.
  std::optional<std::string> agree_on_error(const std::optional<std::string>& mine) const;
  // The same, with the rank it came from (unprefixed).
  struct RankMessage {
    int rank;
    std::string text;
  };
  std::optional<RankMessage> first_message(const std::optional<std::string>& mine) const;
  // Sends rank 0's `v` (its size included) to every rank.
  void broadcast(std::vector<std::uint64_t>& v) const;

 private:
  struct Single {};
  explicit ProcessGroup(Single) {}
  int rank_ = 0, size_ = 1;
  const FiberlabMpiCalls* mpi_ = nullptr;  // null: this process alone
};

// Thrown on ranks other than 0 when a rank failed: rank 0 reports the error
// once, the others leave quietly with a non-zero status.
struct FailedElsewhere {};

}  // namespace fiberlab::sim
