// fiberlab's MPI module: the calls of sim/run/mpi_calls.h on Open MPI (or any
// MPI), loaded by ProcessGroup when an MPI launcher started the process.
// Only the calling (main) thread talks to MPI (MPI_THREAD_FUNNELED).
#include "sim/run/mpi_calls.h"

#include <mpi.h>

#include <algorithm>

namespace {

void init(int* rank, int* size) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, rank);
  MPI_Comm_size(MPI_COMM_WORLD, size);
}

void finalize() { MPI_Finalize(); }

// MPI counts are ints: the calls below go in pieces of at most 2^24 elements.
constexpr std::size_t kPiece = std::size_t{1} << 24;

void max_int64(std::int64_t* v, std::size_t n) {
  for (std::size_t i = 0; i < n; i += kPiece)
    MPI_Allreduce(MPI_IN_PLACE, v + i, static_cast<int>(std::min(kPiece, n - i)), MPI_INT64_T,
                  MPI_MAX, MPI_COMM_WORLD);
}

// Adds unsigned 128-bit integers (MPI has no such type: two uint64 words).
void add_u128(void* in, void* inout, int* len, MPI_Datatype*) {
  const auto* a = static_cast<const unsigned __int128*>(in);
  auto* b = static_cast<unsigned __int128*>(inout);
  for (int i = 0; i < *len; ++i) b[i] += a[i];
}

void sum_u128_to_root(unsigned __int128* v, std::size_t n) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Datatype word;
  MPI_Type_contiguous(2, MPI_UINT64_T, &word);
  MPI_Type_commit(&word);
  MPI_Op op;
  MPI_Op_create(add_u128, /*commute=*/1, &op);
  for (std::size_t i = 0; i < n; i += kPiece) {
    const int count = static_cast<int>(std::min(kPiece, n - i));
    if (rank == 0)
      MPI_Reduce(MPI_IN_PLACE, v + i, count, word, op, 0, MPI_COMM_WORLD);
    else
      MPI_Reduce(v + i, nullptr, count, word, op, 0, MPI_COMM_WORLD);
  }
  MPI_Op_free(&op);
  MPI_Type_free(&word);
}

int min_int(int v) {
  int least = v;
  MPI_Allreduce(&v, &least, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return least;
}

void broadcast(void* data, std::size_t bytes, int root) {
  auto* p = static_cast<char*>(data);
  for (std::size_t i = 0; i < bytes; i += kPiece)
    MPI_Bcast(p + i, static_cast<int>(std::min(kPiece, bytes - i)), MPI_BYTE, root, MPI_COMM_WORLD);
}

constexpr FiberlabMpiCalls kCalls{kFiberlabMpiAbi, init,    finalize, max_int64,
                                  sum_u128_to_root, min_int, broadcast};

}  // namespace

extern "C" __attribute__((visibility("default"))) const FiberlabMpiCalls* fiberlab_mpi_calls() {
  return &kCalls;
}
