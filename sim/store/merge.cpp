#include "sim/store/merge.h"

#include "sim/store/result_file.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "common/error.h"
#include "common/units.h"
#include "common/result_layout.h"
#include "sim/store/result_stream.h"

namespace fiberlab::sim {

namespace {

// Everything that must agree between inputs: all settings but the seed, the
// photon count, the output name and the incident directions' lists.
std::string comparable(Settings s) {
  s.seed = 0;
  s.photons = 1;
  s.output.clear();
  s.source.theta_i = {0.0};
  s.source.phi_i = {0.0};
  return to_yaml(s);
}

// " (A has `a`, B `b`)": the first line where the configs of files A and B
// differ, or nothing when they agree line by line (the bins' edges differ then).
std::string first_difference(const std::string& name_a, const std::string& here, const std::string& name_b,
                             const std::string& there) {
  std::istringstream a(here), b(there);
  std::string x, y;
  while (true) {
    const bool more_a = static_cast<bool>(std::getline(a, x)), more_b = static_cast<bool>(std::getline(b, y));
    if (!more_a && !more_b) return "";
    if (!more_a || !more_b || x != y) return fmt::format(" ({} has `{}`, {} `{}`)", name_a, x, name_b, y);
  }
}

std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

// A direction by value; NaN phi_i (a randomly rotated fiber) compares equal to itself.
struct Direction {
  double theta_i, phi_i;
  bool operator<(const Direction& o) const {
    if (theta_i != o.theta_i) return theta_i < o.theta_i;
    if (std::isnan(phi_i) || std::isnan(o.phi_i)) return !std::isnan(phi_i) && std::isnan(o.phi_i);
    return phi_i < o.phi_i;
  }
};

std::string describe(const Direction& d) {
  return std::isnan(d.phi_i)
             ? fmt::format("theta_i = {:.10g} deg, phi_i uniform", rad_to_deg(d.theta_i))
             : fmt::format("theta_i = {:.10g} deg, phi_i = {:.10g} deg", rad_to_deg(d.theta_i),
                           rad_to_deg(d.phi_i));
}

struct Source {
  std::size_t input, k;
};

// The inputs' headers checked against the first one.
void check_compatible(const std::vector<std::unique_ptr<ResultReader>>& readers,
                      const std::vector<std::string>& names) {
  const ResultFile& first = readers[0]->header();
  const std::string reference = comparable(first.settings);
  for (std::size_t i = 0; i < readers.size(); ++i) {
    const ResultFile& h = readers[i]->header();
    if (i > 0 && (comparable(h.settings) != reference ||
                  h.grid.theta_edges != first.grid.theta_edges ||
                  h.grid.phi_edges != first.grid.phi_edges))
      throw Error(fmt::format("merge: {} does not match {}{}: fiber, roughness, tally, segment, "
                              "polarization and estimator settings must be identical (seed, photons and "
                              "incident directions may differ)",
                              names[i], names[0], first_difference(names[i], comparable(h.settings), names[0], reference)));
    const std::vector<Settings::Incidence> inc = h.settings.incidences();
    for (std::size_t k = 0; k < inc.size(); ++k)
      if (inc.size() != h.theta_i.size() || bits(inc[k].theta_i) != bits(h.theta_i[k]) ||
          (bits(inc[k].phi_i) != bits(h.phi_i[k]) && !(std::isnan(inc[k].phi_i) && std::isnan(h.phi_i[k]))))
        throw Error(fmt::format("merge: {}: /source does not match its config_yaml", names[i]));
  }
}

}  // namespace

MergeSummary merge_result_files(const std::vector<std::string>& inputs, const std::string& output) {
  if (inputs.size() < 2) throw Error("merge: give at least two result files");
  for (const std::string& p : inputs) {
    std::error_code ec;
    if (std::filesystem::equivalent(p, output, ec))
      throw Error(fmt::format("merge: the output {} is one of the inputs", output));
  }
  std::vector<std::unique_ptr<ResultReader>> readers;
  // Every input is first validated whole by read_result (shapes against the
  // stored config before allocating, finite sums, a balanced ledger), one
  // file at a time: its one-line errors are the reader's. Then the merge
  // itself streams one incident direction at a time.
  // TODO(merge): a streaming validator would avoid holding one whole input
  // in memory during this pass.
  for (const std::string& p : inputs) (void)read_result(p);
  for (const std::string& p : inputs) readers.push_back(std::make_unique<ResultReader>(p));
  check_compatible(readers, inputs);

  // Every direction, the inputs holding it, and the seeds already in it.
  std::map<Direction, std::vector<Source>> sources;
  std::map<Direction, std::map<std::uint64_t, std::size_t>> seeds_in;
  std::set<double> thetas, phis;
  for (std::size_t i = 0; i < readers.size(); ++i) {
    const ResultFile& h = readers[i]->header();
    for (std::size_t k = 0; k < h.theta_i.size(); ++k) {
      const Direction d{h.theta_i[k], h.phi_i[k]};
      for (std::uint64_t s : readers[i]->direction_seeds()[k]) {
        const auto [it, fresh] = seeds_in[d].emplace(s, i);
        if (!fresh)
          throw Error(fmt::format("merge: {} repeats seed {} at {} (already in {}): the same "
                                  "photons would be counted twice", inputs[i], s, describe(d),
                                  inputs[it->second]));
      }
      sources[d].push_back({i, k});
      thetas.insert(d.theta_i);
      if (!std::isnan(d.phi_i)) phis.insert(d.phi_i);
    }
  }
  const bool uniform = readers[0]->header().settings.source.phi_i_uniform;
  if (sources.size() != thetas.size() * (uniform ? 1 : phis.size()))
    throw Error(fmt::format("merge: the inputs' {} incident directions do not form a theta_i x "
                            "phi_i grid ({} theta_i x {} phi_i): a result file holds a grid",
                            sources.size(), thetas.size(), phis.size()));

  // The merged header: the first input's settings with the union of the lists.
  ResultFile header = readers[0]->header();
  Settings& s = header.settings;
  s.source.theta_i.assign(thetas.begin(), thetas.end());
  if (!uniform) s.source.phi_i.assign(phis.begin(), phis.end());
  std::set<std::uint64_t> all_seeds;
  DirectionSeeds direction_seeds;
  std::uint64_t max_photons = 0;
  for (const auto& [d, seeds] : seeds_in) {
    direction_seeds.emplace_back();
    for (const auto& [seed, input] : seeds) {
      all_seeds.insert(seed);
      direction_seeds.back().push_back(seed);
    }
  }
  header.theta_i.clear();
  header.phi_i.clear();
  for (const auto& [d, from] : sources) {
    header.theta_i.push_back(d.theta_i);
    header.phi_i.push_back(d.phi_i);
    std::uint64_t n = 0;
    for (const Source& src : from) n += readers[src.input]->header().photons[src.k];
    max_photons = std::max(max_photons, n);
  }
  s.seed = *all_seeds.begin();
  s.photons = max_photons;  // per direction, the largest: /tally/photons has each one
  s.output = output;
  header.seeds.assign(all_seeds.begin(), all_seeds.end());
  header.config_yaml = to_yaml(s);
  header.created_utc = utc_timestamp();
  header.software_version = FIBERLAB_VERSION;

  ResultWriter writer(output, header, direction_seeds);
  MergeSummary summary;
  std::size_t k = 0;
  for (const auto& [d, from] : sources) {
    ExactTally sum(readers[0]->shape());
    for (const Source& src : from) sum += readers[src.input]->read(src.k);
    writer.write(k++, sum);
    if (from.size() > 1) ++summary.summed_directions;
  }
  writer.commit();
  summary.directions = sources.size();
  return summary;
}

}  // namespace fiberlab::sim
