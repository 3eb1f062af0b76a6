#include "compare/atlas_checkpoint.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <type_traits>

#include "analytic/model_registry.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "compare/atlas_file.h"
#include "compare/fit.h"
#include "sim/run/settings.h"

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

// Strings of many fibers and models in one attribute: one per line, with
// "\" and line breaks escaped so that any text survives.
std::string escaped(const std::string& text) {
  std::string out;
  for (char ch : text) {
    if (ch == '\\') out += "\\\\";
    else if (ch == '\n') out += "\\n";
    else if (ch == '\r') out += "\\r";
    else out += ch;
  }
  return out;
}

std::string lines_attr(const std::vector<std::string>& items) {
  std::string s;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i) s += '\n';
    s += escaped(items[i]);
  }
  return s;
}

// The inverse of lines_attr for one line or more; nullopt when an escape is
// malformed.
std::optional<std::vector<std::string>> from_lines_attr(const std::string& text) {
  std::vector<std::string> out(1);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    if (ch == '\n') {
      out.emplace_back();
    } else if (ch != '\\') {
      out.back() += ch;
    } else if (i + 1 < text.size() && (text[i + 1] == '\\' || text[i + 1] == 'n' || text[i + 1] == 'r')) {
      const char e = text[++i];
      out.back() += e == 'n' ? '\n' : e == 'r' ? '\r' : '\\';
    } else {
      return std::nullopt;
    }
  }
  return out;
}

// The numbers of every fiber, flattened in the sweep's order: a handful of
// datasets whatever the number of fibers. (One dataset per fiber and model
// made each rewrite grow as the square of the fibers, HDF5 flushing its
// metadata after each dataset: measured 0.3 s at 32 fibers, 6 s at 128.)
struct Flat {
  std::vector<std::uint64_t> photons, shape, model_state;
  std::vector<double> seconds, theta_i, sim_energy, sim_error, model_seconds, comparisons, fit_numbers, fit_values;
  std::vector<std::string> labels, status, params_before, params_after, fit_keys;
  // fit.per_lobe: per fiber and model (lobe fits, their comparison rows)
  // and status; per lobe fit its lobe and fit numbers, its keys' values and
  // its status line. Its comparison rows follow the model's "after" rows in
  // `comparisons`.
  std::vector<std::uint64_t> lobe_fit_state;
  std::vector<double> lobe_fit_numbers, lobe_fit_values;
  std::vector<std::string> lobe_fit_status, lobe_fit_lines;
};

constexpr std::size_t kFitNumbers = 7;  // chi2_start, chi2, residuals, dof, iterations, evaluations, converged
constexpr std::size_t kFitValues = 5;   // per key: start, value, error, error_unscaled, at_bound

void add_comparisons(Flat& flat, const std::vector<LobeComparison>& list) {
  for (const LobeComparison& c : list)
    for_each_field(c, [&](const char*, const auto& x) { flat.comparisons.push_back(static_cast<double>(x)); });
}

void add_fit_numbers(std::vector<double>& numbers, std::vector<double>& values, const FitResult& fit) {
  for (double x : {fit.chi2_start, fit.chi2, double(fit.residuals), double(fit.dof), double(fit.iterations),
                   double(fit.evaluations), double(fit.converged)})
    numbers.push_back(x);
  for (std::size_t j = 0; j < fit.keys.size(); ++j)
    for (double x : {fit.start[j], fit.value[j], fit.error[j], fit.error_unscaled[j], double(fit.at_bound[j])})
      values.push_back(x);
}

void add_fit(Flat& flat, const FitResult& fit) {
  flat.fit_keys.push_back(joined(fit.keys, ","));
  add_fit_numbers(flat.fit_numbers, flat.fit_values, fit);
}

void add_lobe_fits(Flat& flat, const AtlasModelResult& m) {
  flat.lobe_fit_state.insert(flat.lobe_fit_state.end(), {m.lobe_fits.size(), m.after_lobe_fit.size()});
  flat.lobe_fit_status.push_back(m.lobe_fit_status);
  for (std::size_t j = 0; j < m.lobe_fits.size(); ++j) {
    flat.lobe_fit_numbers.push_back(m.lobe_fits[j].lobe);
    add_fit_numbers(flat.lobe_fit_numbers, flat.lobe_fit_values, m.lobe_fits[j].fit);
    flat.lobe_fit_lines.push_back(m.lobe_fit_lines.at(j));
  }
  add_comparisons(flat, m.after_lobe_fit);
}

Flat flatten(const std::vector<AtlasFiberResult>& fibers, bool per_lobe) {
  Flat flat;
  for (const AtlasFiberResult& r : fibers) {
    flat.labels.push_back(r.fiber.label);
    flat.photons.push_back(r.photons);
    flat.shape.insert(flat.shape.end(), {std::uint64_t(r.lobes), std::uint64_t(r.channels)});
    flat.seconds.insert(flat.seconds.end(), {r.sim_seconds, r.fit_seconds});
    flat.theta_i.insert(flat.theta_i.end(), r.theta_i.begin(), r.theta_i.end());
    flat.sim_energy.insert(flat.sim_energy.end(), r.sim_energy.begin(), r.sim_energy.end());
    flat.sim_error.insert(flat.sim_error.end(), r.sim_error.begin(), r.sim_error.end());
    for (const AtlasModelResult& m : r.models) {
      flat.model_state.insert(flat.model_state.end(), {std::uint64_t(m.applicable), std::uint64_t(m.fitted),
                                                       m.before.size(), m.after.size()});
      flat.model_seconds.push_back(m.seconds);
      flat.status.push_back(m.status);
      flat.params_before.push_back(m.params_before);
      flat.params_after.push_back(m.params_after);
      add_comparisons(flat, m.before);
      add_comparisons(flat, m.after);
      if (per_lobe) add_lobe_fits(flat, m);
      if (m.fitted && !m.fit.keys.empty()) add_fit(flat, m.fit);
    }
  }
  return flat;
}

// FNV-1a (64 bits) of an array's values as stored (little-endian 8-byte
// words): /dataset_digests holds one per dataset, in kDigestOrder, so that
// datasets swapped or edited within their shapes (sim_energy and sim_error
// share one) are refused.
template <class T>
std::uint64_t values_digest(const std::vector<T>& v) {
  static_assert(sizeof(T) == 8);
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const T& x : v) {
    unsigned char b[8];
    std::memcpy(b, &x, 8);
    for (unsigned char c : b) h = (h ^ c) * 0x100000001b3ULL;
  }
  return h;
}

constexpr const char* kDigestOrder =
    "photons,shape,seconds,theta_i,sim_energy,sim_error,model_state,model_seconds,comparisons,"
    "fit_numbers,fit_values";
// With fit.per_lobe, the per-lobe fits' datasets in /lobe_fit_digests.
constexpr const char* kLobeFitDigestOrder = "lobe_fit_state,lobe_fit_numbers,lobe_fit_values";
constexpr std::size_t kLobeFitNumbers = 1 + kFitNumbers;  // lobe, then as fit_numbers

template <class Arrays>
std::vector<std::uint64_t> dataset_digests(const Arrays& a, const std::vector<double>& fit_numbers,
                                           const std::vector<double>& fit_values) {
  return {values_digest(a.photons),      values_digest(a.shape),       values_digest(a.seconds),
          values_digest(a.theta_i),      values_digest(a.sim_energy),  values_digest(a.sim_error),
          values_digest(a.model_state),  values_digest(a.model_seconds),
          values_digest(a.comparisons),  values_digest(fit_numbers),   values_digest(fit_values)};
}

std::vector<std::uint64_t> lobe_fit_digests(const std::vector<std::uint64_t>& state, const std::vector<double>& numbers,
                                            const std::vector<double>& values) {
  return {values_digest(state), values_digest(numbers), values_digest(values)};
}

void write_lobe_fits(h5::File& f, const Flat& flat, std::size_t F, std::size_t M) {
  f.set_attr("/", "lobe_fit_digest_order", std::string(kLobeFitDigestOrder));
  f.set_attr("/", "lobe_fit_digests",
             lobe_fit_digests(flat.lobe_fit_state, flat.lobe_fit_numbers, flat.lobe_fit_values));
  f.set_attr("/", "lobe_fit_status", lines_attr(flat.lobe_fit_status));
  f.set_attr("/", "lobe_fit_lines", lines_attr(flat.lobe_fit_lines));
  write_described(f, "/lobe_fit_state", {F, M, 2}, flat.lobe_fit_state, "fiber,model,field", "",
                  "(per-lobe fits, their comparison rows) per fiber and model (fit.per_lobe)");
  if (!flat.lobe_fit_lines.empty()) {
    write_described(f, "/lobe_fit_numbers", {flat.lobe_fit_lines.size(), kLobeFitNumbers}, flat.lobe_fit_numbers,
                    "lobe_fit,field", "",
                    "lobe, chi2_start, chi2, residuals, dof, iterations, evaluations, converged per per-lobe fit");
    write_described(f, "/lobe_fit_values", {flat.lobe_fit_values.size() / kFitValues, kFitValues},
                    flat.lobe_fit_values, "fit_key,field", "the key's unit (degrees for angles)",
                    "start, value, error, error_unscaled, at_bound per key of each per-lobe fit");
  }
}

void write_flat(h5::File& f, const Flat& flat, std::size_t F, std::size_t K, std::size_t M, bool per_lobe) {
  if (per_lobe) write_lobe_fits(f, flat, F, M);
  f.set_attr("/", "dataset_digest_order", std::string(kDigestOrder));
  f.set_attr("/", "dataset_digests", dataset_digests(flat, flat.fit_numbers, flat.fit_values));
  const std::size_t columns = comparison_columns().size();
  f.set_attr("/", "fiber_labels", lines_attr(flat.labels));
  f.set_attr("/", "status", lines_attr(flat.status));
  f.set_attr("/", "params_before", lines_attr(flat.params_before));
  f.set_attr("/", "params_after", lines_attr(flat.params_after));
  f.set_attr("/", "fit_keys", lines_attr(flat.fit_keys));
  f.set_attr("/", "comparison_columns", joined(comparison_columns(), ","));
  const char* energies = "each saved fiber's K x L x C lobe energies (its own L, C), one fiber after another";
  write_described(f, "/photons", {F}, flat.photons, "fiber", "photons", "photons per incident direction");
  write_described(f, "/shape", {F, 2}, flat.shape, "fiber,field", "", "(lobes, channels) of each fiber");
  write_described(f, "/seconds", {F, 2}, flat.seconds, "fiber,field", "seconds",
                  "wall time of the simulation, of the comparisons and fits");
  write_described(f, "/theta_i", {F, K}, flat.theta_i, "fiber,incidence", "radians", "incident inclinations");
  write_described(f, "/sim_energy", {flat.sim_energy.size()}, flat.sim_energy, "fiber_incidence_lobe_channel",
                  "fraction of incident light", std::string("simulated lobe energies: ") + energies);
  write_described(f, "/sim_error", {flat.sim_error.size()}, flat.sim_error, "fiber_incidence_lobe_channel",
                  "fraction of incident light", std::string("standard errors of sim_energy: ") + energies);
  write_described(f, "/model_state", {F, M, 4}, flat.model_state, "fiber,model,field", "",
                  "(applicable, fitted, comparison rows before, rows after) per fiber and model");
  write_described(f, "/model_seconds", {F, M}, flat.model_seconds, "fiber,model", "seconds",
                  "wall time of each model's comparison and fit");
  if (!flat.comparisons.empty())
    write_described(f, "/comparisons", {flat.comparisons.size() / columns, columns}, flat.comparisons, "row,field", "",
                    "per fiber and model, its LobeComparison rows (compare/comparison.h) before, then after "
                    "the fit (then, with fit.per_lobe, after each lobe's own fit); fields named by "
                    "comparison_columns, each in its member's unit");
  if (!flat.fit_numbers.empty()) {
    write_described(f, "/fit_numbers", {flat.fit_numbers.size() / kFitNumbers, kFitNumbers}, flat.fit_numbers,
                    "fitted_model,field", "",
                    "chi2_start, chi2, residuals, dof, iterations, evaluations, converged per fitted model");
    write_described(f, "/fit_values", {flat.fit_values.size() / kFitValues, kFitValues}, flat.fit_values,
                    "fit_key,field", "the key's unit (degrees for angles)",
                    "start, value, error, error_unscaled, at_bound per key of each fitted model");
  }
}

// ---- reading: every value checked before it is used ----

struct Reader {
  const h5::File& f;
  const std::string& path;

  [[noreturn]] void fail(const std::string& what) const { throw Error(fmt::format("{}: {}", path, what)); }

  std::string text(const std::string& obj, const char* name) const { return f.attr_string(obj, name); }
  std::vector<std::string> lines(const char* name, std::size_t count, const char* each) const {
    const std::string stored = text("/", name);
    if (count == 0 && stored.empty()) return {};  // no line (lines_attr of nothing)
    const auto out = from_lines_attr(stored);
    if (!out || out->size() != count)
      fail(fmt::format("attribute {} must hold {} line(s), one per {}", name, count, each));
    return *out;
  }
  std::vector<double> doubles(const std::string& name, const h5::Dims& shape, const std::string& meaning) const {
    return f.read_doubles(name, shape, meaning);
  }
};

// A stored number into a member of its type: integers must be integral and
// in range (unsigned ones >= 0), flags 0 or 1.
template <class T>
T from_cell(const Reader& r, double v, const std::string& where) {
  if constexpr (std::is_same_v<T, bool>) {
    if (v != 0.0 && v != 1.0) r.fail(fmt::format("{} = {} must be 0 or 1", where, v));
    return v == 1.0;
  } else if constexpr (std::is_integral_v<T>) {
    const double lo = std::is_signed_v<T> ? static_cast<double>(std::numeric_limits<int>::min()) : 0.0;
    if (!(v >= lo && v <= static_cast<double>(std::numeric_limits<int>::max()) && v == std::floor(v)))
      r.fail(fmt::format("{} = {} must be an integer{}", where, v, lo == 0.0 ? " >= 0" : ""));
    return static_cast<T>(v);
  } else {
    return v;
  }
}

// Walks the flat arrays in the order flatten() wrote them.
struct Cursor {
  std::size_t energy = 0, comparison = 0, fit = 0, fit_value = 0, lobe_fit = 0, lobe_fit_value = 0;
};

std::vector<LobeComparison> read_comparisons(const Reader& r, const std::vector<double>& cells, std::size_t rows,
                                             Cursor& at, const AtlasFiberResult& fiber, const std::string& where) {
  const std::size_t columns = comparison_columns().size();
  std::vector<LobeComparison> out;
  for (std::size_t row = 0; row < rows; ++row, ++at.comparison) {
    if ((at.comparison + 1) * columns > cells.size())
      r.fail("the dataset comparisons has fewer rows than model_state counts");
    LobeComparison c;
    std::size_t j = 0;
    for_each_field(c, [&](const char* field, auto& x) {
      x = from_cell<std::remove_reference_t<decltype(x)>>(r, cells[at.comparison * columns + j++],
                                                          fmt::format("{}[{}].{}", where, row, field));
    });
    if (c.bins.dof < 0 || c.theta_marginal.dof < 0 || c.phi_marginal.dof < 0)
      r.fail(fmt::format("{}[{}]: a degree-of-freedom count is negative", where, row));
    // k, lobe and channel index the output's arrays (negative ones were refused above).
    if (c.k >= fiber.theta_i.size() || c.lobe >= fiber.lobes || c.channel >= fiber.channels)
      r.fail(fmt::format("{}[{}]: (k, lobe, channel) = ({}, {}, {}) is outside the fiber's {} x {} x {}", where, row,
                         c.k, c.lobe, c.channel, fiber.theta_i.size(), fiber.lobes, fiber.channels));
    out.push_back(c);
  }
  return out;
}

struct FitArrays {
  std::vector<double> numbers, values;
  std::vector<std::string> keys;
};

// A fit of `keys` from its row of numbers `n` (fit_numbers' fields) and its
// keys' rows of `values` from `value_at` on; the parameters at the minimum
// as fit_model made them: `start` with each key set to its fitted value.
FitResult fit_from(const Reader& r, const double* n, const std::vector<double>& values, std::size_t& value_at,
                   const std::vector<std::string>& keys, const std::string& model,
                   const analytic::ModelParameters& start, const std::string& where) {
  FitResult fit;
  fit.keys = keys;
  fit.chi2_start = n[0];
  fit.chi2 = n[1];
  fit.residuals = from_cell<int>(r, n[2], where + ".fit.residuals");
  fit.dof = from_cell<int>(r, n[3], where + ".fit.dof");
  fit.iterations = from_cell<int>(r, n[4], where + ".fit.iterations");
  fit.evaluations = from_cell<int>(r, n[5], where + ".fit.evaluations");
  fit.converged = from_cell<bool>(r, n[6], where + ".fit.converged");
  if ((value_at + fit.keys.size()) * kFitValues > values.size())
    r.fail(fmt::format("{}: fewer rows of fitted values than the fitted keys", where));
  for (std::size_t j = 0; j < fit.keys.size(); ++j, ++value_at) {
    const double* v = &values[value_at * kFitValues];
    fit.start.push_back(v[0]);
    fit.value.push_back(v[1]);
    fit.error.push_back(v[2]);
    fit.error_unscaled.push_back(v[3]);
    fit.at_bound.push_back(from_cell<bool>(r, v[4], where + ".fit.at_bound"));
  }
  // The outcome follows from these (fit_model's rule: a fit that moves
  // nothing takes no iteration and has NaN errors, compare/fit.h NotFitted);
  // the stop reason is kept in the model's status line (a per-lobe fit's in
  // its lobe_fit_lines).
  const bool bound = std::find(fit.at_bound.begin(), fit.at_bound.end(), true) != fit.at_bound.end();
  const bool not_fitted = !fit.converged && fit.iterations == 0 && !fit.error.empty() &&
                          std::all_of(fit.error.begin(), fit.error.end(), [](double e) { return std::isnan(e); });
  fit.outcome = not_fitted       ? FitOutcome::NotFitted
                : !fit.converged ? FitOutcome::NotConverged
                : bound          ? FitOutcome::AtBound
                                 : FitOutcome::Converged;
  try {
    fit.params = start;
    for (std::size_t j = 0; j < fit.keys.size(); ++j) set_parameter(model, fit.params, fit.keys[j], fit.value[j]);
  } catch (const Error& e) {
    r.fail(fmt::format("{}: the fitted parameters are refused by {}: {}", where, model, e.what()));
  }
  return fit;
}

FitResult read_fit(const Reader& r, const FitArrays& fits, Cursor& at, const AtlasConfig& config,
                   const AtlasFiber& fiber, const std::string& entry, const std::string& where) {
  if (at.fit >= fits.keys.size()) r.fail("fit_keys has fewer lines than fitted models");
  const std::string& model = registered_model(config, entry);
  const std::vector<std::string> keys = free_fit_keys(model);
  if (fits.keys[at.fit] != joined(keys, ","))
    r.fail(fmt::format("{}: fit keys {} are not {}'s free keys {}", where, fits.keys[at.fit], model,
                       joined(keys, ",")));
  analytic::ModelParameters start;
  try {
    start = atlas_start_params(config, fiber, entry);
  } catch (const Error& e) {
    r.fail(fmt::format("{}: the fitted parameters are refused by {}: {}", where, model, e.what()));
  }
  const double* n = &fits.numbers[at.fit * kFitNumbers];
  ++at.fit;
  return fit_from(r, n, fits.values, at.fit_value, keys, model, start, where);
}

// Everything of the file, each array read with the shape the config and
// model_state give it; then walked fiber by fiber.
struct LobeFitArrays {
  std::vector<std::uint64_t> state;
  std::vector<double> numbers, values;
  std::vector<std::string> status, lines;
};

struct Stored {
  std::vector<std::string> labels, status, params_before, params_after;
  std::vector<std::uint64_t> photons, shape, model_state;
  std::vector<double> seconds, theta_i, sim_energy, sim_error, model_seconds, comparisons;
  FitArrays fits;
  LobeFitArrays lobe_fits;  // fit.per_lobe
};

// fit.per_lobe's arrays; returns the comparison rows they count. Their
// values are checked against /lobe_fit_digests here (the rest of the file's
// against /dataset_digests once it is read).
std::size_t read_lobe_fits(const Reader& r, std::size_t F, const AtlasConfig& config, LobeFitArrays& out) {
  const std::size_t M = config.models.size();
  out.state = r.f.read_uint64s("lobe_fit_state", {F, M, 2}, "fibers_saved x models x 2");
  out.status = r.lines("lobe_fit_status", F * M, "saved fiber and model");
  std::size_t fits = 0, rows = 0, keys = 0;
  for (std::size_t i = 0; i < F; ++i)
    for (std::size_t m = 0; m < M; ++m) {
      const std::uint64_t* st = &out.state[(i * M + m) * 2];
      // tally_lobes(): a medulla's `scattered` lobe is fitted lobe by lobe too.
      const std::uint64_t L = config.fibers[i].settings.tally_lobes(), C = config.fibers[i].settings.fiber.sigma_a.size();
      if (st[0] > L || st[1] > config.theta_i.size() * L * C)
        r.fail(fmt::format("lobe_fit_state of fiber {}, model {} is out of range", i + 1, config.models[m]));
      fits += st[0];
      rows += st[1];
      keys += st[0] * free_fit_keys(registered_model(config, config.models[m])).size();
    }
  out.lines = r.lines("lobe_fit_lines", fits, "per-lobe fit");
  if (fits > 0) {
    out.numbers = r.doubles("lobe_fit_numbers", {fits, kLobeFitNumbers}, "one row per per-lobe fit");
    out.values = r.doubles("lobe_fit_values", {keys, kFitValues}, "one row per key of each per-lobe fit");
  }
  if (!r.f.has_attr("/", "lobe_fit_digests") || r.text("/", "lobe_fit_digest_order") != kLobeFitDigestOrder)
    r.fail("its per-lobe fit digests are missing (written by another build?)");
  if (r.f.attr_uint64s("/", "lobe_fit_digests", 64) != lobe_fit_digests(out.state, out.numbers, out.values))
    r.fail("the per-lobe fit datasets do not hold the values written with them (their digests in "
           "/lobe_fit_digests differ: datasets swapped, edited or damaged)");
  return rows;
}

Stored read_stored(const Reader& r, std::size_t F, const AtlasConfig& config) {
  const std::size_t K = config.theta_i.size(), M = config.models.size(), columns = comparison_columns().size();
  if (r.text("/", "comparison_columns") != joined(comparison_columns(), ","))
    r.fail("its comparison columns are not this build's (resume it with the fiberlab build that wrote it)");
  Stored s;
  s.labels = r.lines("fiber_labels", F, "saved fiber");
  s.status = r.lines("status", F * M, "saved fiber and model");
  s.params_before = r.lines("params_before", F * M, "saved fiber and model");
  s.params_after = r.lines("params_after", F * M, "saved fiber and model");
  s.photons = r.f.read_uint64s("photons", {F}, "fibers_saved");
  s.shape = r.f.read_uint64s("shape", {F, 2}, "fibers_saved x (lobes, channels)");
  s.seconds = r.doubles("seconds", {F, 2}, "fibers_saved x (simulation, fits)");
  s.theta_i = r.doubles("theta_i", {F, K}, "fibers_saved x theta_i");
  s.model_state = r.f.read_uint64s("model_state", {F, M, 4}, "fibers_saved x models x 4");
  std::size_t energies = 0, rows = 0, fitted = 0, fitted_keys = 0;
  for (std::size_t i = 0; i < F; ++i) {
    const AtlasFiber& fiber = config.fibers[i];
    // The result's lobes: the tally's, and `scattered` after them with a medulla (docs/FUR.md).
    const std::uint64_t L = fiber.settings.tally_lobes(), C = fiber.settings.fiber.sigma_a.size();
    if (s.shape[2 * i] != L || s.shape[2 * i + 1] != C)
      r.fail(fmt::format("shape of fiber {} = ({}, {}) is not its config's (lobes {}, channels {})", i + 1,
                         s.shape[2 * i], s.shape[2 * i + 1], L, C));
    energies += K * L * C;
    for (std::size_t m = 0; m < M; ++m) {
      const std::uint64_t* st = &s.model_state[(i * M + m) * 4];
      if (st[0] > 1 || st[1] > 1 || st[2] > K * L * C || st[3] > K * L * C)
        r.fail(fmt::format("model_state of fiber {}, model {} is out of range", i + 1, config.models[m]));
      rows += st[2] + st[3];
      const std::size_t P = free_fit_keys(registered_model(config, config.models[m])).size();
      if (st[1] == 1 && P > 0) {
        ++fitted;
        fitted_keys += P;
      }
    }
  }
  if (config.per_lobe) rows += read_lobe_fits(r, F, config, s.lobe_fits);
  s.sim_energy = r.doubles("sim_energy", {energies}, "theta_i x lobes x channels of every saved fiber");
  s.sim_error = r.doubles("sim_error", {energies}, "theta_i x lobes x channels of every saved fiber");
  s.model_seconds = r.doubles("model_seconds", {F, M}, "fibers_saved x models");
  if (rows > 0) s.comparisons = r.doubles("comparisons", {rows, columns}, "the rows model_state counts");
  s.fits.keys = r.lines("fit_keys", fitted, "fitted model");
  if (fitted > 0) {
    s.fits.numbers = r.doubles("fit_numbers", {fitted, kFitNumbers}, "one row per fitted model");
    s.fits.values = r.doubles("fit_values", {fitted_keys, kFitValues}, "one row per fitted key");
  }
  return s;
}

AtlasModelResult read_model(const Reader& r, const Stored& s, Cursor& at, const AtlasConfig& config,
                            const AtlasFiberResult& fiber, std::size_t i, std::size_t m) {
  const std::size_t M = config.models.size(), at_im = i * M + m;
  const std::uint64_t* st = &s.model_state[at_im * 4];
  AtlasModelResult out;
  out.model = config.models[m];
  const std::string where = fmt::format("fiber {}, model {}", i + 1, out.model);
  out.applicable = st[0] == 1;
  out.fitted = st[1] == 1;
  out.status = s.status[at_im];
  out.params_before = s.params_before[at_im];
  out.params_after = s.params_after[at_im];
  out.seconds = s.model_seconds[at_im];
  out.before = read_comparisons(r, s.comparisons, st[2], at, fiber, where + ", before");
  out.after = read_comparisons(r, s.comparisons, st[3], at, fiber, where + ", after");
  std::uint64_t lobe_fit_count = 0;
  if (out.fitted && !out.applicable) r.fail(where + ": fitted but not applicable");
  const std::string& model = registered_model(config, out.model);
  if (config.per_lobe) {
    const std::uint64_t* lst = &s.lobe_fits.state[at_im * 2];
    out.lobe_fit_status = s.lobe_fits.status[at_im];
    out.after_lobe_fit = read_comparisons(r, s.comparisons, lst[1], at, fiber, where + ", after per-lobe fit");
    lobe_fit_count = lst[0];
  }
  if (out.fitted && !free_fit_keys(model).empty()) {
    out.fit = read_fit(r, s.fits, at, config, fiber.fiber, out.model, where);
    if (analytic::describe_params(model, out.fit.params) != out.params_after)
      r.fail(where + ": the fitted values do not give params_after");
  }
  if (lobe_fit_count > 0 && !out.fitted) r.fail(where + ": fitted lobe by lobe but not jointly");
  for (std::uint64_t j = 0; j < lobe_fit_count; ++j, ++at.lobe_fit) {
    const double* n = &s.lobe_fits.numbers[at.lobe_fit * kLobeFitNumbers];
    LobeFit lf;
    lf.lobe = from_cell<int>(r, n[0], where + ".lobe_fit.lobe");
    if (lf.lobe < 0 || lf.lobe >= fiber.lobes) r.fail(fmt::format("{}: per-lobe fit of lobe {} is outside the fiber's {} lobes", where, lf.lobe, fiber.lobes));
    const std::string lobe_where = fmt::format("{}, per-lobe fit of {}", where, fiber_lobe_names(fiber.fiber).at(static_cast<std::size_t>(lf.lobe)));
    const std::vector<std::string> lobe_keys = per_lobe_keys(model, out.fit.keys, lf.lobe);
    lf.fit = fit_from(r, n + 1, s.lobe_fits.values, at.lobe_fit_value, lobe_keys, model,
                      lobe_fit_start(model, out.fit.params, lobe_keys), lobe_where);  // as fit_each_lobe starts
    out.lobe_fits.push_back(std::move(lf));
    out.lobe_fit_lines.push_back(s.lobe_fits.lines[at.lobe_fit]);
  }
  return out;
}

AtlasFiberResult read_fiber(const Reader& r, const Stored& s, Cursor& at, const AtlasConfig& config, std::size_t i) {
  const std::size_t K = config.theta_i.size();
  AtlasFiberResult out;
  out.fiber = config.fibers[i];
  if (s.labels[i] != out.fiber.label)
    r.fail(fmt::format("fiber {} is \"{}\", not the config's \"{}\"", i + 1, s.labels[i], out.fiber.label));
  out.lobes = static_cast<int>(s.shape[2 * i]);
  out.channels = static_cast<int>(s.shape[2 * i + 1]);
  out.photons = s.photons[i];
  out.sim_seconds = s.seconds[2 * i];
  out.fit_seconds = s.seconds[2 * i + 1];
  out.theta_i.assign(s.theta_i.begin() + i * K, s.theta_i.begin() + (i + 1) * K);
  const std::size_t n = K * out.lobes * out.channels;
  out.sim_energy.assign(s.sim_energy.begin() + at.energy, s.sim_energy.begin() + at.energy + n);
  out.sim_error.assign(s.sim_error.begin() + at.energy, s.sim_error.begin() + at.energy + n);
  at.energy += n;
  for (std::size_t m = 0; m < config.models.size(); ++m) out.models.push_back(read_model(r, s, at, config, out, i, m));
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
  for (const auto& [variant, model] : config.variant_of) s += fmt::format("variant {}: model {}\n", variant, model);
  for (const auto& [model, settings] : config.model_parameters)
    s += fmt::format("model_parameters.{}: {}\n", model, joined(settings, " "));
  s += fmt::format("fit.max_iterations: {}\n", config.max_iterations);
  // Absent, the identity is the same as without the key.
  for (const auto& [entry, settings] : config.fit_model_parameters)
    s += fmt::format("fit.model_parameters.{}: {}\n", entry, joined(settings, " "));
  // fit.lobes and fit.per_lobe change the results; absent, the identity is the same as without these keys.
  if (!config.fit_lobes.empty()) {
    s += "fit.lobes:";
    for (int l : config.fit_lobes) s += fmt::format(" {}", l);
    s += "\n";
  }
  if (config.per_lobe) s += "fit.per_lobe: true\n";
  s += "theta_i (rad):";
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
    write_atlas_axis_names(f, config);
    if (!fibers.empty())
      write_flat(f, flatten(fibers, config.per_lobe), fibers.size(), config.theta_i.size(), config.models.size(),
                 config.per_lobe);
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
  if (saved == 0) return c;
  const Stored stored = read_stored(r, saved, c.config);
  Cursor at;
  for (std::size_t i = 0; i < saved; ++i) c.fibers.push_back(read_fiber(r, stored, at, c.config, i));
  if (at.comparison * comparison_columns().size() != stored.comparisons.size() ||
      at.fit_value * kFitValues != stored.fits.values.size() ||
      at.lobe_fit_value * kFitValues != stored.lobe_fits.values.size())
    r.fail("it holds more comparisons or fitted values than its models");
  // Last, so that a value out of range is named first: values that pass
  // every check but are not those written (datasets swapped or edited).
  if (!f.has_attr("/", "dataset_digests") || r.text("/", "dataset_digest_order") != kDigestOrder)
    r.fail("its dataset digests are missing (written by another build?)");
  const std::vector<std::uint64_t> want = f.attr_uint64s("/", "dataset_digests", 64),
                                   got = dataset_digests(stored, stored.fits.numbers, stored.fits.values);
  std::string order = kDigestOrder;
  std::replace(order.begin(), order.end(), ',', '\n');
  const std::vector<std::string> names = lines_of(order);
  for (std::size_t d = 0; d < got.size(); ++d)
    if (d >= want.size() || want[d] != got[d])
      r.fail(fmt::format("dataset {} does not hold the values written with it (its digest in "
                         "/dataset_digests differs: datasets swapped, edited or damaged)",
                         names[d]));
  return c;
}

namespace {

AtlasConfig one_fiber_config(const AtlasConfig& config, std::size_t index) {
  AtlasConfig one = config;
  one.fibers = {config.fibers.at(index)};
  return one;
}

// Removes the scratch file however the caller leaves.
struct ScratchFile {
  std::string path;
  ~ScratchFile() {
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
};

}  // namespace

std::vector<std::uint8_t> pack_atlas_fiber(const AtlasConfig& config, std::size_t index,
                                           const AtlasFiberResult& result, const std::string& scratch) {
  const AtlasConfig one = one_fiber_config(config, index);
  const ScratchFile file{scratch};
  {
    h5::File f = h5::File::create(scratch);
    write_flat(f, flatten({result}, one.per_lobe), 1, one.theta_i.size(), one.models.size(), one.per_lobe);
    f.close();
  }
  std::ifstream in(scratch, std::ios::binary);
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw Error(fmt::format("{}: cannot read back the packed fiber", scratch));
  return bytes;
}

AtlasFiberResult unpack_atlas_fiber(const AtlasConfig& config, std::size_t index,
                                    const std::vector<std::uint8_t>& bytes, const std::string& scratch) {
  const AtlasConfig one = one_fiber_config(config, index);
  const ScratchFile file{scratch};
  {
    std::ofstream out(scratch, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw Error(fmt::format("{}: cannot write the received fiber", scratch));
  }
  const h5::File f = h5::File::open_read(scratch);
  const std::string origin = fmt::format("fiber {} received from another rank", index + 1);
  const Reader r{f, origin};
  const Stored stored = read_stored(r, 1, one);
  Cursor at;
  AtlasFiberResult result = read_fiber(r, stored, at, one, 0);
  result.fiber = config.fibers.at(index);
  return result;
}

std::string describe_atlas_checkpoint(const std::string& path) {
  const h5::File f = h5::File::open_read(path);
  return fmt::format("{}: fiberlab atlas checkpoint (software {}, created {})\nconfig {}, output {} (in the "
                     "checkpoint's folder): {} of {} fibers saved\nresume with: fiberlab atlas --resume {}\n",
                     path, f.attr_string("/", "software_version"), f.attr_string("/", "created_utc"),
                     f.attr_string("/", "config_path"), f.attr_string("/", "output_name"),
                     f.attr_uint64("/", "fibers_saved"), f.attr_uint64("/", "fibers_total"), path);
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
