#pragma once
// The checkpoint of `fiberlab atlas` (docs/ATLAS.md "Interrupting and
// resuming"): OUT.checkpoint.h5, named as `fiberlab run`'s
// (sim::checkpoint_path), rewritten atomically (common/atomic_output.h)
// after each fiber is finished, holding every fiber finished so far, complete
// (its simulated lobe energies and every model's comparisons and fit), and
// how the run was started: the config's text, the --photons flag, OUT, the
// report folder, the command line, and the identity of the config it ran
// (atlas_config_identity). A resumed atlas skips the saved fibers and writes
// the same file and report as an uninterrupted run: the fibers are simulated
// and fitted one after another, each depending only on the config (the
// simulation's sums are exact, its photons seeded by index; the fits are
// deterministic), and the saved ones are restored bit for bit (float64).
//
// Format "fiber-atlas-checkpoint" (docs/FILE_FORMAT.md): format_version,
// software_version as every fiberlab file, checkpoint_version below; the
// setup and identity as root attributes; every saved fiber's numbers
// flattened into a dozen datasets (the sweep's order), its strings into
// line-per-entry attributes. Only the fiberlab version that wrote a
// checkpoint resumes it.
#include <cstdint>
#include <string>
#include <vector>

#include "compare/atlas.h"
#include "compare/atlas_config.h"

namespace fiberlab::compare {

inline constexpr int kAtlasCheckpointVersion = 1;

// What the checkpoint restores on --resume: the run as it was started.
struct AtlasRunSetup {
  std::string config_path;   // the config file as given (names it in the report and errors)
  std::string config_yaml;   // its text
  std::string photons_flag;  // --photons as given, "" when absent
  std::string output_name;   // OUT's file name; its folder is the checkpoint's
  std::string report_dir;    // --report made absolute, "" for the default (next to OUT)
  std::string command;       // the command line the report shows
};

// The normalised config that decides the results: every fiber's label and
// simulator settings as sim::to_yaml writes them (photons, seed, roughness,
// absorption, tally... every key explicit, doubles exact), theta_i, the
// models, their fixed parameters, the fit's iteration limit and, when given,
// fit.lobes and fit.per_lobe. Two configs
// with the same identity give the same atlas (comments and key order do not
// matter).
std::string atlas_config_identity(const AtlasConfig& config);

// The config of a setup: its text parsed again, --photons applied.
AtlasConfig atlas_config_of(const AtlasRunSetup& setup);

struct AtlasCheckpoint {
  AtlasRunSetup setup;
  AtlasConfig config;                    // atlas_config_of(setup)
  std::vector<AtlasFiberResult> fibers;  // the sweep's first fibers.size() fibers, in order
};

// Written atomically (temporary file, then rename): an interrupt or a crash
// leaves the previous checkpoint or the new one, never a mix.
void write_atlas_checkpoint(const std::string& path, const AtlasRunSetup& setup, const AtlasConfig& config,
                            const std::vector<AtlasFiberResult>& fibers);

// Reads and checks a checkpoint: every failure (not an HDF5 file, a
// truncated one, another format or fiberlab version, a config that no
// longer parses to the stored identity, a missing or misshapen dataset, an
// index out of range) is one fiberlab::Error naming the file.
// AtlasFiberResult::fiber is the config's; FitResult::params is rebuilt
// exactly as fit_model made it (atlas_start_params plus the fitted values).
AtlasCheckpoint read_atlas_checkpoint(const std::string& path);

// What `fiberlab info` prints for a checkpoint: the config and output it
// runs, the fibers saved of the sweep's, the command that resumes it (from
// the root attributes alone; --resume checks the rest).
std::string describe_atlas_checkpoint(const std::string& path);

// Refuses resuming with a config whose identity is not the checkpoint's
// (--photons of the checkpoint applied to it first): one line naming the
// checkpoint, the config and the first line that differs.
void check_same_atlas_config(const AtlasCheckpoint& checkpoint, const AtlasConfig& given,
                             const std::string& checkpoint_file);

// One finished fiber as bytes, for `mpirun ... fiberlab atlas` (the rank
// that ran it sends them to rank 0): the checkpoint's datasets for this
// fiber alone, as an HDF5 file written to and read from `scratch` (a path
// of the calling process's own; removed afterwards). Exact: every number
// is stored as computed, so the unpacked result equals the packed one.
std::vector<std::uint8_t> pack_atlas_fiber(const AtlasConfig& config, std::size_t index,
                                           const AtlasFiberResult& result, const std::string& scratch);
AtlasFiberResult unpack_atlas_fiber(const AtlasConfig& config, std::size_t index,
                                    const std::vector<std::uint8_t>& bytes, const std::string& scratch);

}  // namespace fiberlab::compare
