#include "sim/run/process_group.h"

#include <dlfcn.h>
#include <fmt/core.h>

#include <cstdlib>

#include "common/error.h"
#include "sim/run/mpi_calls.h"

namespace fiberlab::sim {

namespace {

// Number of processes an MPI launcher started (1 when none did): Open MPI's
// mpirun sets OMPI_COMM_WORLD_SIZE, PMI/PMIx launchers (srun, hydra) PMI_SIZE.
int launched_processes() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  if (std::getenv("PMIX_RANK") || std::getenv("PMI_RANK")) return 2;  // size unknown: > 1 likely
  return 1;
}

// fiberlab's MPI module (sim/run/mpi/), from the build that compiled this file.
// RTLD_GLOBAL: Open MPI's own plugins resolve MPI's symbols through it. Never
// unloaded (MPI cannot be restarted in a process anyway).
const FiberlabMpiCalls& load_mpi_module(int launched) {
#ifdef FIBERLAB_MPI_MODULE
  (void)launched;
  void* module = dlopen(FIBERLAB_MPI_MODULE, RTLD_NOW | RTLD_GLOBAL);
  if (!module)
    throw Error(fmt::format("cannot load fiberlab's MPI module: {} (rebuild fiberlab)",
                            dlerror()));
  const auto calls = reinterpret_cast<const FiberlabMpiCalls* (*)()>(dlsym(module, "fiberlab_mpi_calls"));
  if (!calls || calls()->abi != kFiberlabMpiAbi)
    throw Error(fmt::format("fiberlab's MPI module {} is from another version of fiberlab "
                            "(rebuild fiberlab)", FIBERLAB_MPI_MODULE));
  return *calls();
#else
  throw Error(fmt::format("started as {} MPI processes, but this fiberlab was built without MPI "
                          "(rebuild with libopenmpi-dev installed, -DFIBERLAB_MPI=ON)", launched));
#endif
}

}  // namespace

ProcessGroup::ProcessGroup() {
  const int launched = launched_processes();
  if (launched <= 1) return;
  const FiberlabMpiCalls& mpi = load_mpi_module(launched);
  mpi.init(&rank_, &size_);
  mpi_ = &mpi;
}

ProcessGroup::~ProcessGroup() {
  if (mpi_) mpi_->finalize();
}

const ProcessGroup& ProcessGroup::single() {
  static const ProcessGroup group{Single{}};
  return group;
}

void ProcessGroup::max(std::vector<std::int64_t>& v) const {
  if (mpi_) mpi_->max_int64(v.data(), v.size());
}

void ProcessGroup::sum_to_root(std::vector<ExactTally::Word>& v) const {
  if (mpi_) mpi_->sum_u128_to_root(v.data(), v.size());
}

std::optional<ProcessGroup::RankMessage> ProcessGroup::first_message(
    const std::optional<std::string>& mine) const {
  if (!mpi_) return mine ? std::optional<RankMessage>(RankMessage{rank_, *mine}) : std::nullopt;
  const int first = mpi_->min_int(mine ? rank_ : size_);
  if (first == size_) return std::nullopt;
  std::string message = rank_ == first ? *mine : std::string();
  std::uint64_t length = message.size();
  mpi_->broadcast(&length, sizeof length, first);
  message.resize(length);
  mpi_->broadcast(message.data(), length, first);
  return RankMessage{first, std::move(message)};
}

std::optional<std::string> ProcessGroup::agree_on_error(const std::optional<std::string>& mine) const {
  std::optional<RankMessage> m = first_message(mine);
  if (!m) return std::nullopt;
  if (m->rank != 0) return fmt::format("rank {}: {}", m->rank, m->text);
  return std::move(m->text);
}

void ProcessGroup::broadcast(std::vector<std::uint64_t>& v) const {
  if (!mpi_) return;
  std::uint64_t n = v.size();
  mpi_->broadcast(&n, sizeof n, 0);
  v.resize(n);
  mpi_->broadcast(v.data(), n * sizeof(std::uint64_t), 0);
}

}  // namespace fiberlab::sim
