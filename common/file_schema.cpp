#include "common/file_schema.h"

#include <fmt/core.h>

namespace fiberlab {

namespace {

std::string lobe_name(int lobe, int lobes) {
  static const char* names[] = {"R", "TT", "TRT", "TRRT", "TR3T", "TR4T"};
  if (lobe == lobes - 1 && lobes > 1) return fmt::format("p>={}", lobe);
  return lobe < 6 ? names[lobe] : fmt::format("p={}", lobe);
}

}  // namespace

std::vector<std::string> lobe_names(int lobes, bool scattered) {
  const int by_p = scattered ? lobes - 1 : lobes;
  std::vector<std::string> out;
  for (int l = 0; l < by_p; ++l) out.push_back(lobe_name(l, by_p));
  if (scattered) out.push_back("scattered");
  return out;
}

std::vector<std::string> channel_names(int channels, bool from_melanin) {
  if (from_melanin && channels == 3) return {"R", "G", "B"};
  std::vector<std::string> out;
  for (int c = 0; c < channels; ++c) out.push_back(fmt::format("c{}", c));
  return out;
}

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

std::vector<std::string> split_names(const std::string& joined) {
  std::vector<std::string> out;
  for (std::size_t a = 0;;) {
    const std::size_t b = joined.find(',', a);
    out.push_back(joined.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) return out;
    a = b + 1;
  }
}

void describe(h5::File& f, const std::string& path, const std::string& dimensions, const std::string& units,
              const std::string& description) {
  if (!dimensions.empty()) f.set_attr(path, "dimensions", dimensions);
  f.set_attr(path, "units", units);
  f.set_attr(path, "description", description);
}

void write_axis_names(h5::File& f, const std::vector<std::string>& lobe_names, int channels, bool from_melanin) {
  f.set_attr("/", "lobe_names", join_names(lobe_names));
  f.set_attr("/", "channel_names", join_names(channel_names(channels, from_melanin)));
}

void describe_bins_and_source(h5::File& f, const AxisPaths& at) {
  describe(f, at.bins + "theta_edges", "theta_edge", "radians",
           "theta_r bin edges, inclination from the plane normal to the fiber axis, in [-pi/2, pi/2]");
  describe(f, at.bins + "phi_edges", "phi_edge", "radians",
           "relative azimuth phi_r - phi_i bin edges, in [-pi, pi]");
  describe(f, at.bins + "solid_angle", "theta,phi", "steradians",
           "(sin theta_hi - sin theta_lo)(phi_hi - phi_lo) per bin");
  describe(f, at.source + "theta_i", "incidence", "radians", "incident inclination per incident direction");
  describe(f, at.source + "phi_i", "incidence", "radians",
           "incident azimuth per incident direction (NaN: randomly rotated fiber)");
}

void describe_tally_photons(h5::File& f) {
  describe(f, "/tally/photons", "incidence", "photons", "photons launched per incident direction (N)");
}

void describe_result_datasets(h5::File& f) {
  describe(f, "/tally/weight_sum", kHistogramDims, "weight",
           "S1: sum of exit weights per bin; probability P = S1/N");
  describe(f, "/tally/weight_sq_sum", kHistogramDims, "weight^2",
           "S2: sum of squared exit weights per bin; standard error of P sqrt((S2/N - P^2)/(N - 1))");
  describe(f, "/tally/count", "incidence,lobe,theta,phi", "photons", "photons scored per bin");
  describe(f, "/ledger/exited", "incidence,lobe,channel", "weight", "weight that left, per lobe (divide by N)");
  describe(f, "/ledger/absorbed", "incidence,channel", "weight", "weight absorbed inside (divide by N)");
  describe(f, "/ledger/truncated", "incidence,channel", "weight",
           "weight still inside when max_segments was reached (divide by N)");
  describe(f, "/ledger/lost", "incidence,channel", "weight",
           "weight removed by masking (roughness.masking smith_g1: 1 - G1 at each event, and paths "
           "killed on the wrong side of the mean surface); 0 otherwise (divide by N)");
  if (f.exists("/tally/lobe_weight_sq_sum"))
    describe(f, "/tally/lobe_weight_sq_sum", "incidence,lobe,channel", "weight^2",
             "per lobe, the sum over photons of the square of each photon's total in the lobe "
             "(estimator expected_value: a photon may leave in several bins of a lobe); the "
             "lobe energy's standard error sqrt((S2/N - E^2)/(N - 1)), E = exited/N");
  if (f.exists("/ledger/roulette"))
    describe(f, "/ledger/roulette", "incidence,channel", "weight",
             "signed: weight Russian roulette created minus weight it destroyed (estimator "
             "expected_value), absorbed along the path before it; expectation 0; exited + "
             "absorbed + truncated + lost - roulette = N (divide by N)");
  describe(f, "/fiber", "", "eta: 1, eccentricity: 1, scale_tilt: radians, sigma_a: 1/R per channel",
           "the fiber's parameters (attributes)");
  describe(f, "/roughness", "", "beta_long, beta_azim: radians; alpha: 1 (slope)",
           "the surface roughness (attributes)");
}

void describe_exact_datasets(h5::File& f) {
  const char* residual =
      "E - (the float64 sum) x 2^60, where E is the exact sum x 2^60 (a 128-bit integer; "
      "docs/FILE_FORMAT.md)";
  describe(f, "/exact/weight_sum_residual", kHistogramDims, "weight x 2^60",
           std::string("exact S1: ") + residual);
  describe(f, "/exact/weight_sq_sum_residual", kHistogramDims, "weight^2 x 2^60",
           std::string("exact S2: ") + residual);
  const char* pairs = "(high, low) 64-bit words of the exact sum x 2^60, an unsigned 128-bit integer";
  describe(f, "/exact/exited", "incidence,lobe,channel,word", "weight x 2^60",
           std::string("exact /ledger/exited: ") + pairs);
  for (const char* name : {"absorbed", "truncated", "lost"})
    describe(f, std::string("/exact/") + name, "incidence,channel,word", "weight x 2^60",
             fmt::format("exact /ledger/{}: {}", name, pairs));
  if (f.exists("/exact/lobe_weight_sq_sum"))
    describe(f, "/exact/lobe_weight_sq_sum", "incidence,lobe,channel,word", "weight^2 x 2^60",
             std::string("exact /tally/lobe_weight_sq_sum: ") + pairs);
  if (f.exists("/exact/roulette"))
    describe(f, "/exact/roulette", "incidence,channel,word", "weight x 2^60",
             "exact /ledger/roulette: (high, low) 64-bit words of the exact sum x 2^60, a signed "
             "128-bit integer in two's complement");
}

}  // namespace fiberlab
