// The validating reader of result files (declared in sim/store/result_file.h).
//
// A result file may come from anywhere (another machine, an h5py script, a
// disk error), so nothing in it is trusted: the stored configuration fixes
// every shape, each dataset's declared shape is compared with it before any
// memory is allocated for the data, and the values are checked against what
// a simulation can produce (SPEC sections 6 and 9).
#include <fmt/core.h>

#include <cmath>
#include <limits>

#include "common/error.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "sim/store/result_file.h"

namespace fiberlab::sim {

namespace {

// merged_seeds: one seed per merged run.
constexpr std::size_t kMaxMergedSeeds = std::size_t{1} << 24;
// Relative tolerance of the ledger balance (exact in the 128-bit tally; the
// float64 conversion rounds each sum by 2^-53).
constexpr double kLedgerTolerance = 1e-9;
// Edges and incident angles must match those the config gives to this
// tolerance (radians); both come from the same code, so they agree exactly
// unless the file was altered.
constexpr double kAngleTolerance = 1e-9;

struct Shape {
  hsize_t K, L, T, P, C;
};

class Reader {
 public:
  Reader(const h5::File& f, std::string path) : f_(f), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(fmt::format("{}: {}", path_, what));
  }

  void identity() const {
    if (!f_.has_attr("/", "format") || f_.attr_string("/", "format") != "fiber-histogram")
      fail("not a fiberlab result file (root attribute format must be \"fiber-histogram\")");
    read_format_version(f_, path_);
    for (const char* name : {"software_version", "created_utc", "config_yaml"})
      if (!f_.has_attr("/", name)) fail(fmt::format("root attribute {} is missing", name));
  }

  std::vector<std::uint64_t> seeds() const {
    if (f_.has_attr("/", "merged_seeds"))
      return f_.attr_uint64s("/", "merged_seeds", kMaxMergedSeeds);
    if (!f_.has_attr("/", "seed")) fail("root attribute seed is missing");
    return {f_.attr_uint64("/", "seed")};
  }

  // Finite and >= 0: sums of weights in [0, 1].
  void check_sums(const std::string& name, const std::vector<double>& v) const {
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!std::isfinite(v[i]) || v[i] < 0.0)
        fail(fmt::format("{} holds {} at flat index {} (must be finite and >= 0)", name, v[i], i));
  }

  void check_angles(const std::string& name, const std::vector<double>& stored,
                    const std::vector<double>& expected) const {
    for (std::size_t i = 0; i < stored.size(); ++i) {
      const bool both_nan = std::isnan(stored[i]) && std::isnan(expected[i]);
      if (!both_nan && !(std::fabs(stored[i] - expected[i]) <= kAngleTolerance))
        fail(fmt::format("{}[{}] = {} does not match config_yaml, which gives {}", name, i,
                         stored[i], expected[i]));
    }
  }

  void check_bins(const BinGrid& stored, const Settings& s) const {
    const BinGrid expected = BinGrid::make(s.tally.n_theta, s.tally.n_phi, s.tally.theta_bins);
    if (stored.theta_binning != expected.theta_binning)
      fail(fmt::format("/bins@theta_bins = {} does not match config_yaml's tally.theta_bins = {}",
                       to_string(stored.theta_binning), to_string(expected.theta_binning)));
    check_angles("/bins/theta_edges", stored.theta_edges, expected.theta_edges);
    check_angles("/bins/phi_edges", stored.phi_edges, expected.phi_edges);
  }

  // Per incident direction: counts in bins <= photons, and the ledger
  // exited + absorbed + truncated + lost = photons for every channel.
  void check_balance(const ResultFile& r, const Shape& d) const {
    const std::size_t bins_per_k = d.L * d.T * d.P;
    for (std::size_t k = 0; k < d.K; ++k) {
      const std::uint64_t n = r.photons[k];
      if (n == 0) fail(fmt::format("/tally/photons[{}] = 0 (must be >= 1)", k));
      unsigned __int128 counted = 0;
      for (std::size_t b = 0; b < bins_per_k; ++b) counted += r.count[k * bins_per_k + b];
      // A photon exits once under the analog estimator; with expected-value
      // scoring it may exit in many bins (each bin counts it once).
      if (r.settings.estimator == Estimator::Analog && counted > n)
        fail(fmt::format("/tally/count sums to {} for incident direction {} (must be at most "
                         "/tally/photons[{}] = {})", static_cast<double>(counted), k, k, n));
      for (std::size_t c = 0; c < d.C; ++c) {
        double total = r.absorbed[k * d.C + c] + r.truncated[k * d.C + c] + r.lost[k * d.C + c] -
                       r.roulette[k * d.C + c];
        for (std::size_t l = 0; l < d.L; ++l) total += r.exited[(k * d.L + l) * d.C + c];
        const double N = static_cast<double>(n);
        if (!(std::fabs(total - N) <= kLedgerTolerance * N))
          fail(fmt::format("/ledger does not balance for incident direction {}, channel {}: "
                           "exited + absorbed + truncated + lost - roulette = {} (must equal "
                           "/tally/photons[{}] = {})",
                           k, c, total, k, n));
      }
    }
  }

 private:
  const h5::File& f_;
  std::string path_;
};

}  // namespace

ResultFile read_result(const std::string& path) {
  const h5::File f = h5::File::open_read(path);
  const Reader rd(f, path);
  rd.identity();

  ResultFile r;
  r.config_yaml = f.attr_string("/", "config_yaml");
  r.settings = parse_stored_settings_yaml(r.config_yaml, path + ":/config_yaml");
  r.software_version = f.attr_string("/", "software_version");
  r.created_utc = f.attr_string("/", "created_utc");
  r.seeds = rd.seeds();

  // Every shape follows from the stored configuration.
  const Settings& s = r.settings;
  const std::vector<Settings::Incidence> inc = s.incidences();
  const Shape d{inc.size(), static_cast<hsize_t>(s.tally_lobes()),
                static_cast<hsize_t>(s.tally.n_theta), static_cast<hsize_t>(s.tally.n_phi),
                s.fiber.sigma_a.size()};
  const std::string sizes = fmt::format("K = {} incident directions, L = {} lobes, n_theta = {}, "
                                        "n_phi = {}, C = {} channels, from config_yaml",
                                        d.K, d.L, d.T, d.P, d.C);
  r.grid = read_bins(f, s.tally.n_theta, s.tally.n_phi, "n_theta + 1 and n_phi + 1, " + sizes);
  rd.check_bins(r.grid, s);
  f.shape("/bins/solid_angle");  // present (derived from the edges; not read)

  r.theta_i = f.read_doubles("/source/theta_i", {d.K}, "K, " + sizes);
  r.phi_i = f.read_doubles("/source/phi_i", {d.K}, "K, " + sizes);
  std::vector<double> theta_expected, phi_expected;
  for (const auto& i : inc) {
    theta_expected.push_back(i.theta_i);
    phi_expected.push_back(i.phi_i);
  }
  rd.check_angles("/source/theta_i", r.theta_i, theta_expected);
  rd.check_angles("/source/phi_i", r.phi_i, phi_expected);

  r.lobes = static_cast<int>(d.L);
  r.channels = static_cast<int>(d.C);
  r.photons = f.read_uint64s("/tally/photons", {d.K}, "K, " + sizes);
  r.weight_sum = f.read_doubles("/tally/weight_sum", {d.K, d.L, d.T, d.P, d.C},
                                "K x L x n_theta x n_phi x C, " + sizes);
  rd.check_sums("/tally/weight_sum", r.weight_sum);
  r.weight_sq_sum = f.read_doubles("/tally/weight_sq_sum", {d.K, d.L, d.T, d.P, d.C},
                                   "K x L x n_theta x n_phi x C, " + sizes);
  rd.check_sums("/tally/weight_sq_sum", r.weight_sq_sum);
  r.count = f.read_uint64s("/tally/count", {d.K, d.L, d.T, d.P}, "K x L x n_theta x n_phi, " + sizes);
  r.exited = f.read_doubles("/ledger/exited", {d.K, d.L, d.C}, "K x L x C, " + sizes);
  rd.check_sums("/ledger/exited", r.exited);
  r.absorbed = f.read_doubles("/ledger/absorbed", {d.K, d.C}, "K x C, " + sizes);
  rd.check_sums("/ledger/absorbed", r.absorbed);
  r.truncated = f.read_doubles("/ledger/truncated", {d.K, d.C}, "K x C, " + sizes);
  rd.check_sums("/ledger/truncated", r.truncated);
  // /ledger/lost (masking): files written before it have none, and lost nothing.
  if (f.exists("/ledger/lost")) {
    r.lost = f.read_doubles("/ledger/lost", {d.K, d.C}, "K x C, " + sizes);
    rd.check_sums("/ledger/lost", r.lost);
  } else {
    r.lost.assign(d.K * d.C, 0.0);
  }
  // /ledger/roulette (signed; expected-value scoring only): absent, 0.
  if (f.exists("/ledger/roulette")) {
    r.roulette = f.read_doubles("/ledger/roulette", {d.K, d.C}, "K x C, " + sizes);
    for (std::size_t i = 0; i < r.roulette.size(); ++i)
      if (!std::isfinite(r.roulette[i]))
        rd.fail(fmt::format("/ledger/roulette holds {} at flat index {} (must be finite)",
                            r.roulette[i], i));
  } else {
    r.roulette.assign(d.K * d.C, 0.0);
  }
  // /tally/lobe_weight_sq_sum (expected-value scoring): absent, the lobes'
  // S2 are their bins' (lobe_energy).
  if (f.exists("/tally/lobe_weight_sq_sum")) {
    r.lobe_weight_sq_sum = f.read_doubles("/tally/lobe_weight_sq_sum", {d.K, d.L, d.C}, "K x L x C, " + sizes);
    rd.check_sums("/tally/lobe_weight_sq_sum", r.lobe_weight_sq_sum);
  }
  rd.check_balance(r, d);
  return r;
}

}  // namespace fiberlab::sim
