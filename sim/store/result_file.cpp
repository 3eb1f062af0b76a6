#include "sim/store/result_file.h"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/h5_file.h"
#include "common/result_layout.h"

namespace fiberlab::sim {

namespace {

template <typename T>
void append(std::vector<T>& to, const std::vector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

void write_parameters(h5::File& f, const Settings& s) {
  write_fiber(f, s.fiber);
  f.set_attr("/source", "max_segments", static_cast<std::int64_t>(s.max_segments));
  f.set_attr("/source", "polarization", to_string(s.polarization));
  f.set_attr("/source", "estimator", to_string(s.estimator));
  f.set_attr("/source", "exit_normals", std::vector<double>(s.exit_normals.begin(), s.exit_normals.end()));
  f.set_attr("/source", "phi_i_uniform", static_cast<std::int64_t>(s.source.phi_i_uniform));
}

}  // namespace

ResultFile make_result(const Settings& settings, const BinGrid& grid,
                       const std::vector<Tally>& tallies) {
  ResultFile r;
  r.settings = settings;
  r.config_yaml = to_yaml(settings);
  r.seeds = {settings.seed};
  r.software_version = FIBERLAB_VERSION;
  r.created_utc = utc_timestamp();
  r.grid = grid;
  for (const Settings::Incidence& inc : settings.incidences()) {
    r.theta_i.push_back(inc.theta_i);
    r.phi_i.push_back(inc.phi_i);
  }
  r.lobes = settings.tally_lobes();
  r.channels = static_cast<int>(settings.fiber.sigma_a.size());
  for (const Tally& t : tallies) {
    r.photons.push_back(t.photons());
    append(r.weight_sum, t.weight_sum());
    append(r.weight_sq_sum, t.weight_sq_sum());
    append(r.count, t.count());
    append(r.exited, t.exited());
    append(r.absorbed, t.absorbed());
    append(r.truncated, t.truncated());
    append(r.lost, t.lost());
    append(r.roulette, t.roulette());
    if (settings.estimator == Estimator::ExpectedValue)
      append(r.lobe_weight_sq_sum, ExactTally::to_double(t.exact_ledger().lobe_weight_sq_sum));
  }
  return r;
}

std::vector<std::string> ResultFile::lobe_names() const {
  return fiberlab::lobe_names(lobes, settings.fiber.medulla.has_value());
}

void write_result_header(h5::File& f, const ResultFile& r) {
  write_file_identity(f, "fiber-histogram", r.created_utc);
  // Exact uint64: every seed in [0, 2^64 - 1] round-trips, and merge tells
  // any two distinct seeds apart.
  f.set_attr("/", "seed", r.seeds.front());
  f.set_attr("/", "merged_seeds", r.seeds);
  f.set_attr("/", "config_yaml", r.config_yaml);
  write_bins(f, r.grid);
  write_incidences(f, r.theta_i, r.phi_i);
  write_parameters(f, r.settings);
}

void describe_result_file(h5::File& f, const ResultFile& r) {
  write_axis_names(f, r.lobe_names(), r.channels, r.settings.fiber.eumelanin.has_value());
  describe_bins_and_source(f);
  describe_result_datasets(f);
  if (f.exists("/exact")) describe_exact_datasets(f);
  if (f.exists("/merge/direction_seeds"))
    describe(f, "/merge/direction_seeds", "row,field", "",
             "(direction index, seed) per row: the seeds summed into each incident direction");
}

void write_result(const ResultFile& r, const std::string& path,
                  const std::vector<std::string>& inputs) {
  AtomicOutput out(path, inputs);
  {
    h5::File f = h5::File::create(out.temp_path(), out.target());
    write_result_header(f, r);

    const hsize_t K = r.configs(), L = r.lobes, C = r.channels;
    const hsize_t T = r.grid.n_theta(), P = r.grid.n_phi();
    f.create_group("/tally");
    f.write("/tally/photons", {K}, r.photons);
    f.write("/tally/weight_sum", {K, L, T, P, C}, r.weight_sum);
    f.write("/tally/weight_sq_sum", {K, L, T, P, C}, r.weight_sq_sum);
    f.write("/tally/count", {K, L, T, P}, r.count);
    f.create_group("/ledger");
    f.write("/ledger/exited", {K, L, C}, r.exited);
    f.write("/ledger/absorbed", {K, C}, r.absorbed);
    f.write("/ledger/truncated", {K, C}, r.truncated);
    f.write("/ledger/lost", {K, C}, r.lost);
    if (r.settings.estimator == Estimator::ExpectedValue) {
      f.write("/ledger/roulette", {K, C}, r.roulette);
      f.write("/tally/lobe_weight_sq_sum", {K, L, C}, r.lobe_weight_sq_sum);
    }
    describe_result_file(f, r);
    describe_tally_photons(f);
    f.close();
  }
  out.commit();
}

Settings load_settings_or_result(const std::string& path) {
  if (!is_hdf5_file(path)) return load_settings(path);
  const h5::File f = h5::File::open_read(path);
  if (!f.has_attr("/", "config_yaml"))
    throw Error(fmt::format("{}: HDF5 file without a config_yaml root attribute (not a fiberlab result)", path));
  return parse_stored_settings_yaml(f.attr_string("/", "config_yaml"), path + ":/config_yaml");
}

Estimate bin_estimate(double s1, double s2, std::uint64_t n) {
  const double N = static_cast<double>(n);
  const double p = s1 / N;
  const double var = n > 1 ? std::max(0.0, (s2 / N - p * p) / (N - 1.0)) : 0.0;
  return {p, std::sqrt(var)};
}

Estimate lobe_energy(const ResultFile& r, std::size_t k, int lobe, int c) {
  const double s1 = r.exited[(k * r.lobes + lobe) * r.channels + c];
  // Expected-value scoring: a photon may leave in several bins of a lobe,
  // and the lobe's S2 is the sum over photons of the square of its total.
  if (!r.lobe_weight_sq_sum.empty())
    return bin_estimate(s1, r.lobe_weight_sq_sum[(k * r.lobes + lobe) * r.channels + c], r.photons[k]);
  // Analog: each photon lands in one bin, so the lobe's S2 is the sum of its bins' S2.
  double s2 = 0.0;
  for (int i = 0; i < r.grid.n_theta(); ++i)
    for (int j = 0; j < r.grid.n_phi(); ++j) s2 += r.weight_sq_sum[r.cell(k, lobe, i, j, c)];
  return bin_estimate(s1, s2, r.photons[k]);
}

}  // namespace fiberlab::sim
