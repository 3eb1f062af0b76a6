#pragma once
// The estimators of SPEC section 6 over a whole result, as fiberlab.Result
// shows them (the arrays keep the result's index order).
#include <string>
#include <vector>

#include "sim/store/result_file.h"

namespace fiberlab::app {

// Per bin (K, L, n_theta, n_phi, C): P = S1/N and its standard error
// (sim::bin_estimate), and P / Omega with its standard error.
struct BinEstimates {
  std::vector<double> mean, std_err, density, density_std_err;
};
BinEstimates bin_estimates(const sim::ResultFile& r);

// The marginal over theta_r (summed over phi) or over phi (summed over
// theta_r), (K, L, n, C) with n its bins: a photon lands in one bin, so a
// marginal bin's S1 and S2 are its bins' sums (then sim::bin_estimate).
// `axis`: "theta" or "phi" (otherwise fiberlab::Error).
struct Marginal {
  int n = 0;
  std::vector<double> mean, std_err;
};
Marginal marginal(const sim::ResultFile& r, const std::string& axis);

}  // namespace fiberlab::app
