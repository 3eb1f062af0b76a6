#pragma once
// The simulation's result file (SPEC section 9; OpenMC's "statepoint"): what
// was counted, with the parameters it was counted for. Written atomically,
// readable by h5py with no project code.
#include <cstdint>
#include <string>
#include <vector>

#include "common/bin_grid.h"
#include "common/h5_file.h"
#include "sim/run/settings.h"
#include "sim/store/tally.h"

namespace fiberlab::sim {

struct ResultFile {
  Settings settings;                 // parsed back from config_yaml on read
  std::string config_yaml;
  std::vector<std::uint64_t> seeds;  // one per run merged into this file
  std::string software_version, created_utc;
  BinGrid grid;
  std::vector<double> theta_i, phi_i;  // K; phi_i NaN where uniform
  int lobes = 0, channels = 0;
  std::vector<std::uint64_t> photons;   // K
  std::vector<double> weight_sum, weight_sq_sum;  // K x L x n_theta x n_phi x C
  std::vector<std::uint64_t> count;     // K x L x n_theta x n_phi
  std::vector<double> exited;           // K x L x C
  std::vector<double> absorbed, truncated;  // K x C
  std::vector<double> lost;  // K x C: removed by masking (0 unless roughness.masking)
  // K x C, signed: weight Russian roulette created minus destroyed (0 with
  // the analog estimator, whose files have no /ledger/roulette).
  std::vector<double> roulette;
  // K x L x C: per lobe, the sum over photons of the square of each one's
  // total there (/tally/lobe_weight_sq_sum, expected-value files); empty
  // for the analog estimator, whose lobe S2 is the sum of its bins' S2.
  std::vector<double> lobe_weight_sq_sum;

  std::size_t configs() const { return photons.size(); }
  // The names of the lobe axis, what the file's attribute `lobe_names` holds
  // (describe_result_file writes these): R, TT, ..., p>=N by p, and
  // `scattered` last for a fiber with a medulla (docs/FUR.md). Every table,
  // line and record that names a lobe of this result takes it from here.
  std::vector<std::string> lobe_names() const;
  std::size_t bin_cells() const {
    return static_cast<std::size_t>(lobes) * grid.n_theta() * grid.n_phi() * channels;
  }
  // Index into weight_sum / weight_sq_sum.
  std::size_t cell(std::size_t k, int lobe, int i_theta, int i_phi, int c) const {
    return (((k * lobes + lobe) * grid.n_theta() + i_theta) * grid.n_phi() + i_phi) *
               channels + c;
  }
};

// Assembles the file contents from a finished run.
ResultFile make_result(const Settings& settings, const BinGrid& grid,
                       const std::vector<Tally>& tallies);

// Atomic (common/atomic_output.h); `inputs` are files the output must not replace.
void write_result(const ResultFile& result, const std::string& path,
                  const std::vector<std::string>& inputs = {});
// Everything but /tally and /ledger: identity, seeds, config, /bins, /source
// and the parameter groups (shared with the streaming writer, sim/store/result_stream).
void write_result_header(h5::File& f, const ResultFile& header);
// The descriptive attributes of a result file (docs/FILE_FORMAT.md): root
// lobe_names and channel_names, and each dataset's dimensions, units and
// description, for /bins, /source, /tally, /ledger and, when the file has
// them, /exact and /merge; all but /tally/photons (describe_tally_photons,
// common/file_schema.h), which the streaming writer writes last. Called by
// every writer of results (write_result; ResultWriter: run, merge,
// checkpoints) once those datasets exist.
void describe_result_file(h5::File& f, const ResultFile& header);
// Reads and validates a result file (sim/store/result_reader.cpp): format and
// format_version, every dataset's shape against K x L x n_theta x n_phi x C
// from the stored config_yaml (checked before anything is allocated), /bins
// and /source against the config, finite non-negative sums, photons >= 1,
// counts and the energy ledger against photons. Throws fiberlab::Error with
// one line naming the file, the dataset or attribute and what is allowed.
ResultFile read_result(const std::string& path);

// (Merging result files: sim/store/merge.h, from their exact sums.)

// The settings of a YAML config, or those stored in a result file's
// config_yaml (told apart by the HDF5 signature).
Settings load_settings_or_result(const std::string& path);

// Estimators of SPEC section 6 for one lobe's total energy (all bins).
struct Estimate {
  double mean, std_error;
};
// (its standard error from lobe_weight_sq_sum where the file has it, else
// from the sum of the lobe's bins' S2)
Estimate lobe_energy(const ResultFile& r, std::size_t k, int lobe, int c);
// Probability P = S1 / N and its standard error sqrt((S2/N - P^2)/(N - 1)).
Estimate bin_estimate(double s1, double s2, std::uint64_t n);

}  // namespace fiberlab::sim
