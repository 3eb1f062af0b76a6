#pragma once
// The MPI calls a run makes, as a table of C functions: the interface between
// fiberlab and its MPI module (libfiberlab_mpi.so, built from sim/run/mpi/), which
// ProcessGroup loads (dlopen) only when an MPI launcher started the process.
// Why a module: linking Open MPI into every program made each run, MPI or not,
// load 9 more shared libraries at start-up (about 7 ms, docs/PERFORMANCE.md).
// Change kFiberlabMpiAbi with any change to the table.
#include <cstddef>
#include <cstdint>

extern "C" {

inline constexpr int kFiberlabMpiAbi = 1;

struct FiberlabMpiCalls {
  int abi;  // kFiberlabMpiAbi of the module
  // MPI_Init_thread (MPI_THREAD_FUNNELED); this process's rank and the size.
  void (*init)(int* rank, int* size);
  void (*finalize)();
  // Element-wise maximum over the ranks, in place on every rank.
  void (*max_int64)(std::int64_t* v, std::size_t n);
  // Element-wise sum of unsigned 128-bit integers over the ranks into rank 0's
  // `v`, in place (other ranks' `v` is left unspecified).
  void (*sum_u128_to_root)(unsigned __int128* v, std::size_t n);
  // Minimum of `v` over the ranks, on every rank.
  int (*min_int)(int v);
  // `bytes` bytes of `root`'s `data` to every rank.
  void (*broadcast)(void* data, std::size_t bytes, int root);
};

// The module's one exported symbol.
const FiberlabMpiCalls* fiberlab_mpi_calls();
}
