// `fiberlab info FILE.h5`: what a fiberlab file of any kind holds
// (docs/FILE_FORMAT.md): result, run checkpoint, prediction, report data,
// atlas, atlas checkpoint.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <memory>

#include "cli/commands.h"
#include "cli/summary_table.h"
#include "common/error.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "compare/atlas_checkpoint.h"
#include "compare/atlas_file.h"
#include "compare/prediction_file.h"
#include "compare/report.h"
#include "sim/store/checkpoint.h"
#include "sim/store/result_file.h"

namespace fiberlab::cli {

namespace {

std::string degrees(const std::vector<double>& radians) {
  std::string s;
  for (double r : radians) s += fmt::format("{}{:g}", s.empty() ? "" : ", ", rad_to_deg(r));
  return "[" + s + "]";
}

void result_info(const std::string& path) {
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
  fmt::print("tally: {} x {} bins ({} theta), {} lobes, {} channels; max_segments {}, polarization {}, "
             "estimator {}\n",
             r.grid.n_theta(), r.grid.n_phi(), to_string(r.grid.theta_binning), r.lobes, r.channels,
             s.max_segments, sim::to_string(s.polarization), sim::to_string(s.estimator));
  print_summary(stdout, r);
}

void info(const std::string& path) {
  const std::string format = file_format(path);
  if (format == "fiber-histogram") {
    if (h5::File::open_read(path).exists("/checkpoint")) fmt::print("{}", sim::describe_checkpoint(path));
    else result_info(path);
  } else if (format == "fiber-prediction") {
    fmt::print("{}", compare::describe_prediction(compare::read_prediction(path)));
  } else if (format == "fiber-report-data") {
    fmt::print("{}", compare::describe_report_data(path));
  } else if (format == "fiber-atlas") {
    fmt::print("{}", compare::describe_atlas_file(path));
  } else if (format == "fiber-atlas-checkpoint") {
    fmt::print("{}", compare::describe_atlas_checkpoint(path));
  } else {
    throw Error(fmt::format("{}: not a fiberlab result file nor any other kind (root attribute format is {}; "
                            "info reads fiber-histogram, fiber-prediction, fiber-report-data, fiber-atlas, "
                            "fiber-atlas-checkpoint)",
                            path, format.empty() ? "missing" : "\"" + format + "\""));
  }
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a fiberlab file: a result (parameters, photons, lobe "
                                               "energies), run checkpoint, prediction, report data, atlas or "
                                               "atlas checkpoint");
  cmd->add_option("file", *path, "A fiberlab HDF5 file (.h5)")->required();
  cmd->callback([path] { info(*path); });
}

}  // namespace fiberlab::cli
