#include "app/info.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include "common/error.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "common/roughness/roughness.h"
#include "common/units.h"
#include "compare/atlas_checkpoint.h"
#include "compare/atlas_file.h"
#include "compare/prediction_file.h"
#include "compare/report.h"
#include "sim/store/checkpoint.h"

namespace fiberlab::app {

namespace {

FileDescription result_info(const std::string& path) {
  FileDescription d;
  d.result = sim::read_result(path);
  const sim::ResultFile& r = *d.result;
  const sim::Settings& s = r.settings;
  std::string& t = d.text;
  t += fmt::format("{}: fiberlab result (software {}, created {})\n", path, r.software_version, r.created_utc);
  std::string seeds;
  for (auto v : r.seeds) seeds += fmt::format("{}{}", seeds.empty() ? "" : ", ", v);
  t += fmt::format("seeds: {}\n", seeds);
  t += fmt::format("fiber: eta {}, eccentricity {}, scale_tilt {:g} deg, sigma_a {}\n", s.fiber.eta,
                   s.fiber.eccentricity, rad_to_deg(s.fiber.scale_tilt), fmt::join(s.fiber.sigma_a, ", "));
  t += fmt::format("roughness: {}\n", roughness::describe(s.fiber.roughness));
  t += fmt::format("tally: {} x {} bins ({} theta), {} lobes, {} channels; max_segments {}, polarization {}, "
                   "estimator {}{}\n",
                   r.grid.n_theta(), r.grid.n_phi(), to_string(r.grid.theta_binning), r.lobes, r.channels,
                   s.max_segments, sim::to_string(s.polarization), sim::to_string(s.estimator),
                   s.estimator == sim::Estimator::ExpectedValue
                       ? fmt::format(" (exit_normals {})", fmt::join(s.exit_normals, ", "))
                       : std::string());
  return d;
}

}  // namespace

FileDescription describe_file(const std::string& path) {
  const std::string format = file_format(path);
  if (format == "fiber-histogram") {
    if (h5::File::open_read(path).exists("/checkpoint")) return {sim::describe_checkpoint(path), std::nullopt};
    return result_info(path);
  }
  if (format == "fiber-prediction") return {compare::describe_prediction(compare::read_prediction(path)), std::nullopt};
  if (format == "fiber-report-data") return {compare::describe_report_data(path), std::nullopt};
  if (format == "fiber-atlas") return {compare::describe_atlas_file(path), std::nullopt};
  if (format == "fiber-atlas-checkpoint") return {compare::describe_atlas_checkpoint(path), std::nullopt};
  throw Error(fmt::format("{}: not a fiberlab result file nor any other kind (root attribute format is {}; "
                          "info reads fiber-histogram, fiber-prediction, fiber-report-data, fiber-atlas, "
                          "fiber-atlas-checkpoint)",
                          path, format.empty() ? "missing" : "\"" + format + "\""));
}

}  // namespace fiberlab::app
