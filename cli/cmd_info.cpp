// `fiberlab info RESULT.h5`: what a result (or prediction) file holds.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <memory>

#include "cli/commands.h"
#include "cli/summary_table.h"
#include "common/units.h"
#include "compare/prediction_file.h"
#include "sim/result_file.h"

namespace fiberlab::cli {

namespace {

std::string degrees(const std::vector<double>& radians) {
  std::string s;
  for (double r : radians) s += fmt::format("{}{:g}", s.empty() ? "" : ", ", rad_to_deg(r));
  return "[" + s + "]";
}

void info(const std::string& path) {
  if (compare::is_prediction_file(path)) {  // info reads predictions too
    fmt::print("{}", compare::describe_prediction(compare::read_prediction(path)));
    return;
  }
  const sim::ResultFile r = sim::read_result(path);
  const sim::Settings& s = r.settings;
  fmt::print("{}: fiberlab result (software {}, created {})\n", path, r.software_version, r.created_utc);
  std::string seeds;
  for (auto v : r.seeds) seeds += fmt::format("{}{}", seeds.empty() ? "" : ", ", v);
  fmt::print("seeds: {}\n", seeds);
  fmt::print("fiber: eta {}, eccentricity {}, scale_tilt {:g} deg, sigma_a {}\n", s.fiber.eta,
             s.fiber.eccentricity, rad_to_deg(s.fiber.scale_tilt), fmt::join(s.fiber.sigma_a, ", "));
  if (s.roughness.microfacet())
    fmt::print("roughness: {}, alpha_long {}, alpha_azim {}, masking {}\n",
               sim::to_string(s.roughness.model), s.roughness.alpha_long, s.roughness.alpha_azim,
               sim::to_string(s.roughness.masking));
  else
    fmt::print("roughness: {}, beta_long {} deg, beta_azim {} deg\n", sim::to_string(s.roughness.model),
               degrees(s.roughness.beta_long), degrees(s.roughness.beta_azim));
  fmt::print("tally: {} x {} bins ({} theta), {} lobes, {} channels; max_segments {}, polarization {}\n",
             r.grid.n_theta(), r.grid.n_phi(), to_string(r.grid.theta_binning), r.lobes, r.channels,
             s.max_segments, sim::to_string(s.polarization));
  print_summary(stdout, r);
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a result file: parameters, photons, lobe energies");
  cmd->add_option("result", *path, "Result file (.h5)")->required();
  cmd->callback([path] { info(*path); });
}

}  // namespace fiberlab::cli
