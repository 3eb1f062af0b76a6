#pragma once
// Checkpoints (OpenMC's restartable statepoints): OUT.checkpoint.h5 is a
// result file (sim/store/result_stream: float64 and exact sums) of the photons
// traced so far, plus /checkpoint:
//   next_photon (K, uint64): photons [0, next_photon[k]) of direction k are in
//                            its sums (whole chunks of Simulation::kChunk)
//   done (K, uint64):        1 once direction k is finished
//   attributes checkpoint_version, chunk, target_batch, target_error.
// A resumed run continues every direction at next_photon[k]; since photon i's
// path depends only on (seed, direction, i) and sums are exact, the finished
// file is bit-identical to an uninterrupted run.
#include <string>

#include "sim/store/result_file.h"
#include "sim/run/simulation.h"

namespace fiberlab::sim {

inline constexpr int kCheckpointVersion = 1;

// OUT.h5 -> OUT.checkpoint.h5 (any other name: NAME.checkpoint.h5).
std::string checkpoint_path(const std::string& output);

// The result header (everything but the sums) of a run of `settings`:
// the output file's and the checkpoint's.
ResultFile result_header(const Settings& settings, const BinGrid& grid);

// Written atomically (temporary file, then rename).
void write_checkpoint(const std::string& path, const Simulation& sim, const RunProgress& state,
                      double target_error);

struct Checkpoint {
  Settings settings;
  double target_error = 0.0;
  RunProgress state;  // tallies only when read with_tallies
};

// Refuses (fiberlab::Error, naming the file) a checkpoint of another fiberlab
// version or checkpoint format, or one whose contents disagree with its config.
Checkpoint read_checkpoint(const std::string& path, bool with_tallies);

// What `fiberlab info` prints for a checkpoint: its output, each incident
// direction's photons so far and whether it is finished, the command that
// resumes it. Read with read_checkpoint (the same refusals).
std::string describe_checkpoint(const std::string& path);

// Refuses resuming with a config (and flags) other than the checkpoint's.
void check_same_config(const Checkpoint& checkpoint, const Settings& given,
                       const std::string& checkpoint_file);

}  // namespace fiberlab::sim
