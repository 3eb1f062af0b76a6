#include "sim/process_group.h"

#include <fmt/core.h>

#include <cstdlib>

#include "common/error.h"

#ifdef FIBERLAB_HAVE_MPI
#include <mpi.h>
#endif

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

#ifdef FIBERLAB_HAVE_MPI
// Adds unsigned 128-bit integers stored as two uint64 words (MPI has no such type).
void add_words(void* in, void* inout, int* len, MPI_Datatype*) {
  const auto* a = static_cast<const ExactTally::Word*>(in);
  auto* b = static_cast<ExactTally::Word*>(inout);
  for (int i = 0; i < *len; ++i) b[i] += a[i];
}
#endif

}  // namespace

ProcessGroup::ProcessGroup() {
  const int launched = launched_processes();
  if (launched <= 1) return;
#ifdef FIBERLAB_HAVE_MPI
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#else
  throw Error(fmt::format("started as {} MPI processes, but this fiberlab was built without MPI "
                          "(rebuild with libopenmpi-dev installed, -DFIBERLAB_MPI=ON)", launched));
#endif
}

ProcessGroup::~ProcessGroup() {
#ifdef FIBERLAB_HAVE_MPI
  if (mpi_) MPI_Finalize();
#endif
}

const ProcessGroup& ProcessGroup::single() {
  static const ProcessGroup group{Single{}};
  return group;
}

void ProcessGroup::max(std::vector<std::int64_t>& v) const {
#ifdef FIBERLAB_HAVE_MPI
  if (mpi_)
    MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_INT64_T, MPI_MAX,
                  MPI_COMM_WORLD);
#else
  (void)v;
#endif
}

void ProcessGroup::sum_to_root(std::vector<ExactTally::Word>& v) const {
#ifdef FIBERLAB_HAVE_MPI
  if (!mpi_) return;
  MPI_Datatype word;
  MPI_Type_contiguous(2, MPI_UINT64_T, &word);
  MPI_Type_commit(&word);
  MPI_Op op;
  MPI_Op_create(add_words, /*commute=*/1, &op);
  // In pieces of at most 2^24 words, below MPI's int counts.
  constexpr std::size_t kPiece = std::size_t{1} << 24;
  for (std::size_t i = 0; i < v.size(); i += kPiece) {
    const int n = static_cast<int>(std::min(kPiece, v.size() - i));
    if (is_root())
      MPI_Reduce(MPI_IN_PLACE, v.data() + i, n, word, op, 0, MPI_COMM_WORLD);
    else
      MPI_Reduce(v.data() + i, nullptr, n, word, op, 0, MPI_COMM_WORLD);
  }
  MPI_Op_free(&op);
  MPI_Type_free(&word);
#else
  (void)v;
#endif
}

std::optional<std::string> ProcessGroup::agree_on_error(const std::optional<std::string>& mine) const {
#ifdef FIBERLAB_HAVE_MPI
  if (!mpi_) return mine;
  int candidate = mine ? rank_ : size_, first = size_;
  MPI_Allreduce(&candidate, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == size_) return std::nullopt;
  std::string message = rank_ == first ? *mine : std::string();
  int length = static_cast<int>(message.size());
  MPI_Bcast(&length, 1, MPI_INT, first, MPI_COMM_WORLD);
  message.resize(length);
  MPI_Bcast(message.data(), length, MPI_CHAR, first, MPI_COMM_WORLD);
  if (first != 0) message = fmt::format("rank {}: {}", first, message);
  return message;
#else
  return mine;
#endif
}

void ProcessGroup::broadcast(std::vector<std::uint64_t>& v) const {
#ifdef FIBERLAB_HAVE_MPI
  if (!mpi_) return;
  std::uint64_t n = v.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  v.resize(n);
  MPI_Bcast(v.data(), static_cast<int>(n), MPI_UINT64_T, 0, MPI_COMM_WORLD);
#else
  (void)v;
#endif
}

}  // namespace fiberlab::sim
