#include "compare/atlas_checkpoint.h"

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <type_traits>

#include "analytic/model_registry.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "compare/fit.h"
#include "sim/settings.h"

namespace fiberlab::compare {

namespace {

constexpr const char* kFormat = "fiber-atlas-checkpoint";

std::string joined(const std::vector<std::string>& items, const char* separator) {
  std::string s;
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? separator : "") + items[i];
  return s;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string fiber_group(std::size_t i) { return fmt::format("/fiber_{}", i); }
std::string model_group(std::size_t i, std::size_t m) { return fmt::format("/fiber_{}/model_{}", i, m); }

// Every field of a LobeComparison, in one place: visit(name, member) for
// each, so that writing (a row of doubles) and reading (the row back, each
// value checked for its type) cannot disagree on the columns.
template <class Comparison, class Visit>
void for_each_field(Comparison& c, Visit&& visit) {
  visit("k", c.k);
  visit("lobe", c.lobe);
  visit("channel", c.channel);
  visit("theta_i", c.theta_i);
  visit("phi_i", c.phi_i);
  visit("sim_energy", c.sim_energy);
  visit("sim_error", c.sim_error);
  visit("model_energy", c.model_energy);
  visit("energy_z", c.energy_z);
  visit("bins_chi2", c.bins.chi2);
  visit("bins_dof", c.bins.dof);
  visit("theta_marginal_chi2", c.theta_marginal.chi2);
  visit("theta_marginal_dof", c.theta_marginal.dof);
  visit("phi_marginal_chi2", c.phi_marginal.chi2);
  visit("phi_marginal_dof", c.phi_marginal.dof);
  visit("compared_bins", c.compared_bins);
  visit("rest_sim", c.rest_sim);
  visit("rest_model", c.rest_model);
  visit("l1", c.l1);
  visit("peak_sim", c.peak_sim);
  visit("peak_model", c.peak_model);
  visit("centroid_sim", c.centroid_sim);
  visit("centroid_sim_error", c.centroid_sim_error);
  visit("centroid_model", c.centroid_model);
  visit("alpha_model", c.alpha_model);
  visit("measured_shift", c.measured_shift);
  visit("judged", c.judged);
}

std::vector<std::string> comparison_columns() {
  std::vector<std::string> names;
  LobeComparison c;
  for_each_field(c, [&](const char* name, auto&) { names.push_back(name); });
  return names;
}

// ---- writing ----

void write_comparisons(h5::File& f, const std::string& group, const std::string& name,
                       const std::vector<LobeComparison>& list) {
  const std::size_t columns = comparison_columns().size();
  f.set_attr(group, name + "_rows", static_cast<std::uint64_t>(list.size()));
  if (list.empty()) return;
  std::vector<double> rows;
  rows.reserve(list.size() * columns);
  for (const LobeComparison& c : list)
    for_each_field(c, [&](const char*, const auto& x) { rows.push_back(static_cast<double>(x)); });
  f.write(group + "/" + name, {list.size(), columns}, rows);
}

void write_fit(h5::File& f, const std::string& g, const FitResult& fit) {
  f.set_attr(g, "fit_keys", joined(fit.keys, "\n"));
  f.set_attr(g, "fit_chi2_start", fit.chi2_start);
  f.set_attr(g, "fit_chi2", fit.chi2);
  f.set_attr(g, "fit_residuals", static_cast<std::int64_t>(fit.residuals));
  f.set_attr(g, "fit_dof", static_cast<std::int64_t>(fit.dof));
  f.set_attr(g, "fit_iterations", static_cast<std::int64_t>(fit.iterations));
  f.set_attr(g, "fit_evaluations", static_cast<std::int64_t>(fit.evaluations));
  f.set_attr(g, "fit_converged", static_cast<std::int64_t>(fit.converged));
  const h5::Dims P{fit.keys.size()};
  f.write(g + "/fit_start", P, fit.start);
  f.write(g + "/fit_value", P, fit.value);
  f.write(g + "/fit_error", P, fit.error);
  f.write(g + "/fit_error_unscaled", P, fit.error_unscaled);
  f.write(g + "/fit_at_bound", P, std::vector<std::uint64_t>(fit.at_bound.begin(), fit.at_bound.end()));
}

void write_model(h5::File& f, const std::string& g, const AtlasModelResult& m) {
  f.create_group(g);
  f.set_attr(g, "model", m.model);
  f.set_attr(g, "status", m.status);
  f.set_attr(g, "params_before", m.params_before);
  f.set_attr(g, "params_after", m.params_after);
  f.set_attr(g, "applicable", static_cast<std::int64_t>(m.applicable));
  f.set_attr(g, "fitted", static_cast<std::int64_t>(m.fitted));
  f.set_attr(g, "seconds", m.seconds);
  write_comparisons(f, g, "before", m.before);
  write_comparisons(f, g, "after", m.after);
  if (m.fitted && !m.fit.keys.empty()) write_fit(f, g, m.fit);
}

void write_fiber(h5::File& f, std::size_t i, const AtlasFiberResult& r) {
  const std::string g = fiber_group(i);
  f.create_group(g);
  f.set_attr(g, "label", r.fiber.label);
  f.set_attr(g, "lobes", static_cast<std::int64_t>(r.lobes));
  f.set_attr(g, "channels", static_cast<std::int64_t>(r.channels));
  f.set_attr(g, "photons", static_cast<std::uint64_t>(r.photons));
  f.set_attr(g, "sim_seconds", r.sim_seconds);
  f.set_attr(g, "fit_seconds", r.fit_seconds);
  f.write(g + "/theta_i", {r.theta_i.size()}, r.theta_i);
  f.write(g + "/sim_energy", {r.sim_energy.size()}, r.sim_energy);
  f.write(g + "/sim_error", {r.sim_error.size()}, r.sim_error);
  for (std::size_t m = 0; m < r.models.size(); ++m) write_model(f, model_group(i, m), r.models[m]);
}

// ---- reading: every value checked before it is used ----

struct Reader {
  const h5::File& f;
  const std::string& path;

  [[noreturn]] void fail(const std::string& what) const { throw Error(fmt::format("{}: {}", path, what)); }

  std::string text(const std::string& obj, const char* name) const { return f.attr_string(obj, name); }
  double real(const std::string& obj, const char* name) const { return f.attr_double(obj, name); }
  std::int64_t integer(const std::string& obj, const char* name, std::int64_t lo, std::int64_t hi) const {
    const std::int64_t v = f.attr_int(obj, name);
    if (v < lo || v > hi) fail(fmt::format("{}@{} = {} is out of range [{}, {}]", obj, name, v, lo, hi));
    return v;
  }
  bool flag(const std::string& obj, const char* name) const { return integer(obj, name, 0, 1) == 1; }
  std::vector<double> doubles(const std::string& name, const h5::Dims& shape, const std::string& meaning) const {
    return f.read_doubles(name, shape, meaning);
  }
};

// A row value into a member of its type: integers must be integral and in
// the type's range, flags 0 or 1.
template <class T>
T from_cell(const Reader& r, double v, const std::string& where) {
  if constexpr (std::is_same_v<T, bool>) {
    if (v != 0.0 && v != 1.0) r.fail(fmt::format("{} = {} must be 0 or 1", where, v));
    return v == 1.0;
  } else if constexpr (std::is_integral_v<T>) {
    if (!(v >= 0.0 && v <= static_cast<double>(std::numeric_limits<int>::max()) && v == std::floor(v)))
      r.fail(fmt::format("{} = {} must be an integer >= 0", where, v));
    return static_cast<T>(v);
  } else {
    return v;
  }
}

std::vector<LobeComparison> read_comparisons(const Reader& r, const std::string& g, const std::string& name,
                                             const AtlasFiberResult& fiber) {
  const std::uint64_t rows = static_cast<std::uint64_t>(
      r.integer(g, (name + "_rows").c_str(), 0, static_cast<std::int64_t>(fiber.theta_i.size()) * fiber.lobes *
                                                    fiber.channels));
  std::vector<LobeComparison> out;
  if (rows == 0) return out;
  const std::vector<std::string> columns = comparison_columns();
  const std::vector<double> cells =
      r.doubles(g + "/" + name, {rows, columns.size()}, fmt::format("{}_rows x {} columns", name, columns.size()));
  for (std::uint64_t row = 0; row < rows; ++row) {
    LobeComparison c;
    std::size_t j = 0;
    for_each_field(c, [&](const char* field, auto& x) {
      x = from_cell<std::remove_reference_t<decltype(x)>>(
          r, cells[row * columns.size() + j++], fmt::format("{}/{}[{}].{}", g, name, row, field));
    });
    if (c.k >= fiber.theta_i.size() || c.lobe >= fiber.lobes || c.channel >= fiber.channels)
      r.fail(fmt::format("{}/{}[{}]: (k, lobe, channel) = ({}, {}, {}) is outside the fiber's {} x {} x {}", g, name,
                         row, c.k, c.lobe, c.channel, fiber.theta_i.size(), fiber.lobes, fiber.channels));
    out.push_back(c);
  }
  return out;
}

FitResult read_fit(const Reader& r, const std::string& g, const AtlasConfig& config, const AtlasFiber& fiber,
                   const std::string& model) {
  FitResult fit;
  fit.keys = lines_of(r.text(g, "fit_keys"));
  const std::vector<std::string> expected = free_fit_keys(model);
  if (fit.keys != expected)
    r.fail(fmt::format("{}@fit_keys = {} are not {}'s free keys {}", g, joined(fit.keys, ","), model,
                       joined(expected, ",")));
  const h5::Dims P{fit.keys.size()};
  const std::string meaning = "one per fit key";
  fit.start = r.doubles(g + "/fit_start", P, meaning);
  fit.value = r.doubles(g + "/fit_value", P, meaning);
  fit.error = r.doubles(g + "/fit_error", P, meaning);
  fit.error_unscaled = r.doubles(g + "/fit_error_unscaled", P, meaning);
  for (std::uint64_t b : r.f.read_uint64s(g + "/fit_at_bound", P, meaning)) {
    if (b > 1) r.fail(fmt::format("{}/fit_at_bound holds {} (must be 0 or 1)", g, b));
    fit.at_bound.push_back(b == 1);
  }
  fit.chi2_start = r.real(g, "fit_chi2_start");
  fit.chi2 = r.real(g, "fit_chi2");
  constexpr std::int64_t kMaxInt = std::numeric_limits<int>::max();
  fit.residuals = static_cast<int>(r.integer(g, "fit_residuals", 0, kMaxInt));
  fit.dof = static_cast<int>(r.integer(g, "fit_dof", std::numeric_limits<int>::min(), kMaxInt));
  fit.iterations = static_cast<int>(r.integer(g, "fit_iterations", 0, kMaxInt));
  fit.evaluations = static_cast<int>(r.integer(g, "fit_evaluations", 0, kMaxInt));
  fit.converged = r.flag(g, "fit_converged");
  // The parameters at the minimum, as fit_model made them: the start
  // parameters with each key set to its fitted value.
  try {
    fit.params = atlas_start_params(config, fiber, model);
    for (std::size_t j = 0; j < fit.keys.size(); ++j) set_parameter(model, fit.params, fit.keys[j], fit.value[j]);
  } catch (const Error& e) {
    r.fail(fmt::format("{}: the fitted parameters are refused by {}: {}", g, model, e.what()));
  }
  return fit;
}

AtlasModelResult read_model(const Reader& r, const std::string& g, const AtlasConfig& config,
                            const AtlasFiberResult& fiber, const std::string& model) {
  AtlasModelResult m;
  m.model = r.text(g, "model");
  if (m.model != model) r.fail(fmt::format("{}@model = {} (the config's model here is {})", g, m.model, model));
  m.status = r.text(g, "status");
  m.params_before = r.text(g, "params_before");
  m.params_after = r.text(g, "params_after");
  m.applicable = r.flag(g, "applicable");
  m.fitted = r.flag(g, "fitted");
  m.seconds = r.real(g, "seconds");
  m.before = read_comparisons(r, g, "before", fiber);
  m.after = read_comparisons(r, g, "after", fiber);
  if (m.fitted && !m.applicable) r.fail(fmt::format("{}: fitted but not applicable", g));
  if (m.fitted && !free_fit_keys(model).empty()) {
    m.fit = read_fit(r, g, config, fiber.fiber, model);
    if (analytic::describe_params(model, m.fit.params) != m.params_after)
      r.fail(fmt::format("{}: the fitted values do not give params_after", g));
  }
  return m;
}

AtlasFiberResult read_fiber(const Reader& r, std::size_t i, const AtlasConfig& config) {
  const std::string g = fiber_group(i);
  AtlasFiberResult out;
  out.fiber = config.fibers[i];
  const std::string label = r.text(g, "label");
  if (label != out.fiber.label)
    r.fail(fmt::format("{}@label = \"{}\" is not the config's fiber {} (\"{}\")", g, label, i + 1, out.fiber.label));
  out.lobes = static_cast<int>(r.integer(g, "lobes", out.fiber.settings.tally.lobes, out.fiber.settings.tally.lobes));
  const auto channels = static_cast<std::int64_t>(out.fiber.settings.fiber.sigma_a.size());
  out.channels = static_cast<int>(r.integer(g, "channels", channels, channels));
  out.photons = r.f.attr_uint64(g, "photons");
  out.sim_seconds = r.real(g, "sim_seconds");
  out.fit_seconds = r.real(g, "fit_seconds");
  const hsize_t K = config.theta_i.size();
  out.theta_i = r.doubles(g + "/theta_i", {K}, "theta_i of the config");
  const h5::Dims KLC{K * static_cast<hsize_t>(out.lobes) * static_cast<hsize_t>(out.channels)};
  out.sim_energy = r.doubles(g + "/sim_energy", KLC, "theta_i x lobes x channels");
  out.sim_error = r.doubles(g + "/sim_error", KLC, "theta_i x lobes x channels");
  for (std::size_t m = 0; m < config.models.size(); ++m)
    out.models.push_back(read_model(r, model_group(i, m), config, out, config.models[m]));
  return out;
}

// The first line where two identities differ, for the error message.
std::string first_difference(const std::string& a, const std::string& b) {
  const std::vector<std::string> x = lines_of(a), y = lines_of(b);
  for (std::size_t i = 0; i < std::max(x.size(), y.size()); ++i) {
    const std::string u = i < x.size() ? x[i] : "(nothing)", v = i < y.size() ? y[i] : "(nothing)";
    if (u != v) return fmt::format("\"{}\" where the checkpoint has \"{}\"", u, v);
  }
  return "none";
}

}  // namespace

std::string atlas_config_identity(const AtlasConfig& config) {
  std::string s = fmt::format("fiberlab atlas config identity {}\nmodels: {}\n", kAtlasCheckpointVersion,
                              joined(config.models, ","));
  for (const auto& [model, settings] : config.model_parameters)
    s += fmt::format("model_parameters.{}: {}\n", model, joined(settings, " "));
  s += fmt::format("fit.max_iterations: {}\ntheta_i (rad):", config.max_iterations);
  for (double t : config.theta_i) s += fmt::format(" {}", t);
  s += "\n";
  for (std::size_t i = 0; i < config.fibers.size(); ++i)
    s += fmt::format("fiber {}: {}\n{}", i + 1, config.fibers[i].label, sim::to_yaml(config.fibers[i].settings));
  return s;
}

AtlasConfig atlas_config_of(const AtlasRunSetup& setup) {
  AtlasConfig config = parse_atlas_config(setup.config_yaml, setup.config_path);
  if (!setup.photons_flag.empty()) override_photons(config, setup.photons_flag);
  return config;
}

void write_atlas_checkpoint(const std::string& path, const AtlasRunSetup& setup, const AtlasConfig& config,
                            const std::vector<AtlasFiberResult>& fibers) {
  AtomicOutput out(path, {setup.config_path});
  {
    h5::File f = h5::File::create(out.temp_path(), path);
    write_file_identity(f, kFormat, utc_timestamp());
    f.set_attr("/", "checkpoint_version", static_cast<std::int64_t>(kAtlasCheckpointVersion));
    f.set_attr("/", "config_path", setup.config_path);
    f.set_attr("/", "config_yaml", setup.config_yaml);
    f.set_attr("/", "photons_flag", setup.photons_flag);
    f.set_attr("/", "output_name", setup.output_name);
    f.set_attr("/", "report_dir", setup.report_dir);
    f.set_attr("/", "command", setup.command);
    f.set_attr("/", "identity", atlas_config_identity(config));
    f.set_attr("/", "fibers_total", static_cast<std::uint64_t>(config.fibers.size()));
    f.set_attr("/", "fibers_saved", static_cast<std::uint64_t>(fibers.size()));
    for (std::size_t i = 0; i < fibers.size(); ++i) write_fiber(f, i, fibers[i]);
    f.close();
  }
  out.commit();
}

AtlasCheckpoint read_atlas_checkpoint(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw Error(fmt::format("{}: no such checkpoint file (an interrupted atlas leaves OUT.checkpoint.h5)", path));
  if (!std::filesystem::is_regular_file(path, ec))
    throw Error(fmt::format("{}: is not a regular file (a checkpoint is OUT.checkpoint.h5)", path));
  const h5::File f = h5::File::open_read(path);
  const Reader r{f, path};
  if (!f.has_attr("/", "format") || r.text("/", "format") != kFormat)
    r.fail(fmt::format("not a fiberlab atlas checkpoint (no format = {}; `fiberlab atlas --resume` takes the "
                       "OUT.checkpoint.h5 an interrupted atlas left)", kFormat));
  const std::string version = f.has_attr("/", "software_version") ? r.text("/", "software_version") : "?";
  const std::int64_t format = f.has_attr("/", "checkpoint_version") ? f.attr_int("/", "checkpoint_version") : -1;
  if (version != FIBERLAB_VERSION || format != kAtlasCheckpointVersion)
    r.fail(fmt::format("written by fiberlab {} (atlas checkpoint format {}); this is fiberlab {} (format {}): "
                       "resume it with the version that wrote it",
                       version, format, FIBERLAB_VERSION, kAtlasCheckpointVersion));
  AtlasCheckpoint c;
  c.setup.config_path = r.text("/", "config_path");
  c.setup.config_yaml = r.text("/", "config_yaml");
  c.setup.photons_flag = r.text("/", "photons_flag");
  c.setup.output_name = r.text("/", "output_name");
  c.setup.report_dir = r.text("/", "report_dir");
  c.setup.command = r.text("/", "command");
  if (c.setup.output_name.empty() || c.setup.output_name.find('/') != std::string::npos)
    r.fail(fmt::format("output_name = \"{}\" must be a file name", c.setup.output_name));
  try {
    c.config = atlas_config_of(c.setup);
  } catch (const Error& e) {
    r.fail(fmt::format("its stored config is refused: {}", e.what()));
  }
  if (atlas_config_identity(c.config) != r.text("/", "identity"))
    r.fail("its stored config does not give its stored identity (written by another build?)");
  const std::uint64_t total = f.attr_uint64("/", "fibers_total"), saved = f.attr_uint64("/", "fibers_saved");
  if (total != c.config.fibers.size() || saved > total)
    r.fail(fmt::format("fibers_saved = {} of fibers_total = {} disagree with its config's {} fibers", saved, total,
                       c.config.fibers.size()));
  for (std::size_t i = 0; i < saved; ++i) c.fibers.push_back(read_fiber(r, i, c.config));
  return c;
}

void check_same_atlas_config(const AtlasCheckpoint& checkpoint, const AtlasConfig& given,
                             const std::string& checkpoint_file) {
  AtlasConfig flagged = given;
  if (!checkpoint.setup.photons_flag.empty()) override_photons(flagged, checkpoint.setup.photons_flag);
  const std::string a = atlas_config_identity(flagged), b = atlas_config_identity(checkpoint.config);
  if (a != b)
    throw Error(fmt::format("{}: the config {} differs from the one this checkpoint was started with (first "
                            "difference: {}); resume with `fiberlab atlas --resume {}` alone, or delete {} to "
                            "start again",
                            checkpoint_file, given.path, first_difference(a, b), checkpoint_file, checkpoint_file));
}

}  // namespace fiberlab::compare
