#pragma once
// Prediction files ("bring your own model"): the bin probabilities of any
// model, written by `fiberlab predict` or by any HDF5 writer (h5py), judged
// by `fiberlab compare RESULT --prediction PRED.h5`.
//
// Format (angles in radians, index order as in result files, SPEC s9):
//   root attribute  format = "fiber-prediction"            (required)
//   /bins/theta_edges   n_theta + 1                          (required)
//   /bins/phi_edges     n_phi + 1                            (required)
//   /source/theta_i     K                                    (required)
//   /source/phi_i       K (NaN for a randomly rotated fiber)  (required)
//   /prediction/probability  K x L x n_theta x n_phi x C, float64: the
//       probability that a photon of incident direction k leaves in lobe l
//       through bin (i, j), channel c (required; finite, >= 0)
//   /prediction attribute model (text, optional); `fiberlab predict` also
//       writes the model's parameters and its approximations there.
#include <string>
#include <vector>

#include "analytic/model_params.h"
#include "common/bin_grid.h"
#include "common/file_schema.h"
#include "sim/store/result_file.h"

namespace fiberlab::compare {

struct PredictionFile {
  std::string path;
  std::string model;           // "" when the file does not say
  std::string format_version;  // "" when absent
  BinGrid grid;
  std::vector<double> theta_i, phi_i;  // K
  int lobes = 0, channels = 0;
  std::vector<double> probability;     // K x L x n_theta x n_phi x C
  std::vector<std::string> approximations;
  // The last lobe is a medulla's `scattered` (docs/FUR.md), which a model
  // never predicts: its bins are zero (app::predict pads them).
  bool scattered = false;
  std::size_t configs() const { return theta_i.size(); }
  // The lobe axis's names (the file's `lobe_names`): the lobes by p (R, TT,
  // ..., p>=N), then `scattered` for a fiber with a medulla.
  std::vector<std::string> lobe_names() const { return fiberlab::lobe_names(lobes, scattered); }
  std::size_t per_config() const {
    return static_cast<std::size_t>(lobes) * grid.n_theta() * grid.n_phi() * channels;
  }
};

// Writes `pred` (grid, theta_i, phi_i, lobes, channels, probability; its
// model is the registry's name) atomically as `fiberlab predict` does: the
// format and identity, the config it was made for, lobe and channel names,
// every dataset described (docs/FILE_FORMAT.md), and /prediction's attributes
// model, approximations and the model's parameters (angles in radians).
// `inputs`: files the output must not replace. Refuses a non-finite
// probability with one line, writing nothing.
void write_prediction(const std::string& path, const PredictionFile& pred, const sim::Settings& settings,
                      const analytic::ModelParameters& params, const std::vector<std::string>& inputs = {});

// Whether `path` is an HDF5 file whose root attribute format is
// "fiber-prediction" (false for anything else, including missing files).
bool is_prediction_file(const std::string& path);

// Reads and checks a prediction file: every required name present, shapes
// consistent, values finite. fiberlab::Error (exit 2) naming the file and
// the offending name otherwise.
PredictionFile read_prediction(const std::string& path);
// The same for judging `result`: the file's declared shape is checked against
// the result's (bins, directions, lobes, channels) before its probabilities
// are read, so a small file declaring a huge array allocates nothing.
PredictionFile read_prediction_for(const std::string& path, const sim::ResultFile& result,
                                   const std::string& result_path);

// A bin probability a model computes as a sum of quadrature terms of both
// signs (marschner2003's TRT glint correction, s5.2.2) can land a rounding
// below zero: fiberlab's own marschner2003 bins reach about -1e-11. Values
// down to -kProbabilityRounding are taken as they are (no bin's statistics
// can resolve them: a bin's standard error is at least 1/N of its photons);
// anything more negative is not a probability.
inline constexpr double kProbabilityRounding = 1e-9;

// Every probability finite and >= -kProbabilityRounding; otherwise
// fiberlab::Error "ORIGIN holds -0.5 at flat index 3 (probabilities must be
// finite and >= 0; ...)". The one check of a prediction's values: files, and
// the Python module's arrays.
void check_probabilities(const double* p, std::size_t n, const std::string& origin);

// The prediction's bin probabilities per incident direction of `result`, in
// the layout of compare(). Bins, incident directions (theta_i, phi_i, same
// order), lobes and channels must match the result's: fiberlab::Error
// naming the first mismatch otherwise.
std::vector<std::vector<double>> prediction_bins_for(const PredictionFile& pred,
                                                     const sim::ResultFile& result,
                                                     const std::string& result_path);

// What `fiberlab info` prints for a prediction file.
std::string describe_prediction(const PredictionFile& pred);

}  // namespace fiberlab::compare
