#include "compare/atlas_file.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "compare/fit.h"

namespace fiberlab::compare {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (std::size_t i = 0; i < lines.size(); ++i) s += (i ? "\n" : "") + lines[i];
  return s;
}

// "KEY=VALUE KEY=VALUE" (an entry's settings, as the variants' attribute).
std::string joined_settings(const std::vector<std::string>& settings) {
  std::string s;
  for (const std::string& kv : settings) {
    if (!s.empty()) s += ' ';
    s += kv;
  }
  return s;
}

// Sizes shared by every array.
struct Shape {
  hsize_t F, K, L, C;
  std::size_t at(std::size_t f, std::size_t k, int l, int c) const { return ((f * K + k) * L + l) * C + c; }
  h5::Dims dims() const { return {F, K, L, C}; }
};

// One dataset and its description (common/file_schema.h): each array is
// named, shaped, written and described in one place.
template <class T>
void put(h5::File& f, const std::string& path, const h5::Dims& dims, const std::vector<T>& data,
         const std::string& dimensions, const std::string& units, const std::string& description) {
  write_described(f, "/" + path, dims, data, dimensions, units, description);
}

void write_fibers(h5::File& f, const Shape& s, const std::vector<AtlasFiberResult>& fibers) {
  f.create_group("fibers");
  std::vector<double> roughness, tilt, ecc, sim_s, fit_s, e(s.F * s.K * s.L * s.C, kNaN), se = e;
  std::vector<std::uint64_t> gi, ai, channels, photons;
  std::vector<std::string> labels, models, absorption;
  for (std::size_t i = 0; i < fibers.size(); ++i) {
    const AtlasFiberResult& r = fibers[i];
    roughness.push_back(r.fiber.roughness);
    tilt.push_back(r.fiber.settings.fiber.scale_tilt);
    ecc.push_back(r.fiber.settings.fiber.eccentricity);
    sim_s.push_back(r.sim_seconds);
    fit_s.push_back(r.fit_seconds);
    gi.push_back(r.fiber.roughness_index);
    ai.push_back(r.fiber.absorption_index);
    channels.push_back(r.channels);
    photons.push_back(r.photons);
    labels.push_back(r.fiber.label);
    models.push_back(r.fiber.roughness_model);
    absorption.push_back(r.fiber.absorption_label);
    for (std::size_t k = 0; k < s.K; ++k)
      for (int l = 0; l < r.lobes; ++l)
        for (int c = 0; c < r.channels; ++c) {
          const std::size_t src = (k * r.lobes + l) * r.channels + c;
          e[s.at(i, k, l, c)] = r.sim_energy[src];
          se[s.at(i, k, l, c)] = r.sim_error[src];
        }
  }
  const h5::Dims F{s.F};
  put(f, "fibers/roughness", F, roughness, "fiber", "degrees (beta) or unitless (alpha)",
      "roughness size: beta_long for gaussian/exit_blur, alpha for microfacet models, 0 smooth");
  put(f, "fibers/roughness_index", F, gi, "fiber", "index", "entry of sweep.roughness");
  put(f, "fibers/absorption_index", F, ai, "fiber", "index", "entry of sweep.absorption");
  put(f, "fibers/scale_tilt", F, tilt, "fiber", "radians", "cuticle scale tilt, towards the root");
  put(f, "fibers/eccentricity", F, ecc, "fiber", "", "minor/major axis ratio");
  put(f, "fibers/channels", F, channels, "fiber", "channels", "channels of this fiber (later channels are NaN)");
  put(f, "fibers/photons", F, photons, "fiber", "photons", "photons per incident direction");
  put(f, "fibers/sim_seconds", F, sim_s, "fiber", "seconds", "wall time of the simulation");
  put(f, "fibers/fit_seconds", F, fit_s, "fiber", "seconds", "wall time of every model's comparison and fit");
  put(f, "fibers/sim_energy", s.dims(), e, kAtlasDims, "fraction of incident light", "simulated lobe energy (ledger)");
  put(f, "fibers/sim_energy_error", s.dims(), se, kAtlasDims, "fraction of incident light",
      "standard error of sim_energy");
  f.set_attr("/fibers", "labels", joined(labels));
  f.set_attr("/fibers", "roughness_models", joined(models));
  f.set_attr("/fibers", "absorption", joined(absorption));
}

// What the file keeps of fits, one row per fit (a fiber's joint fit, or a
// fiber's fit of one lobe) and P keys a row; NaN (0) where no fit was made.
struct FitColumns {
  std::size_t P;
  std::vector<double> value, error, unscaled, start, bound, chi2_start, chi2, dof, iterations;
  std::vector<std::uint64_t> converged;

  FitColumns(std::size_t rows, std::size_t keys)
      : P(keys), value(rows * keys, kNaN), error(rows * keys, kNaN), unscaled(rows * keys, kNaN),
        start(rows * keys, kNaN), bound(rows * keys, kNaN), chi2_start(rows, kNaN), chi2(rows, kNaN),
        dof(rows, kNaN), iterations(rows, kNaN), converged(rows, 0) {}

  void set(std::size_t row, const FitResult& fit) {
    for (std::size_t k = 0; k < P && k < fit.keys.size(); ++k) {
      value[row * P + k] = fit.value[k];
      error[row * P + k] = fit.error[k];
      unscaled[row * P + k] = fit.error_unscaled[k];
      start[row * P + k] = fit.start[k];
      bound[row * P + k] = fit.at_bound[k] ? 1.0 : 0.0;
    }
    chi2_start[row] = fit.chi2_start;
    chi2[row] = fit.chi2;
    dof[row] = fit.dof;
    iterations[row] = fit.iterations;
    converged[row] = fit.converged;
  }
};

// fit.per_lobe: each lobe's own fit (compare/atlas.h) beside the joint one,
// in the model's group: per fiber and lobe its fitted values, chi-square and
// outcome, and the comparison of that lobe at its own values.
void write_lobe_fits(h5::File& f, const Shape& s, const std::string& g, const std::string& model,
                     const std::vector<std::string>& keys, const std::vector<AtlasFiberResult>& fibers,
                     std::size_t m) {
  const hsize_t P = keys.size(), FL = s.F * s.L;
  const std::size_t n = s.F * s.K * s.L * s.C;
  std::vector<double> energy(n, kNaN), chi2(n, kNaN), dof(n, kNaN);
  FitColumns fits(FL, P);
  std::vector<std::uint64_t> fitted(FL, 0);
  std::vector<std::string> status, lines(FL), lobe_keys;
  for (std::size_t i = 0; i < fibers.size(); ++i) {
    const AtlasModelResult& r = fibers[i].models[m];
    status.push_back(r.lobe_fit_status);
    for (std::size_t j = 0; j < r.lobe_fits.size(); ++j) {
      const LobeFit& lf = r.lobe_fits[j];
      const std::size_t at = i * s.L + lf.lobe;
      fitted[at] = lf.fit.outcome != FitOutcome::NotFitted;  // else its line says why not
      lines[at] = r.lobe_fit_lines.at(j);
      fits.set(at, lf.fit);
    }
    for (const LobeComparison& c : r.after_lobe_fit) {
      const std::size_t at = s.at(i, c.k, c.lobe, c.channel);
      energy[at] = c.model_energy;
      chi2[at] = c.bins.chi2;
      dof[at] = c.bins.dof;
    }
  }
  const bool any = std::any_of(fibers.begin(), fibers.end(), [&](const AtlasFiberResult& r) {
    return !r.models[m].lobe_fits.empty();
  });
  for (hsize_t l = 0; l < s.L; ++l) {
    std::string k;
    if (any)
      for (const std::string& key : per_lobe_keys(model, keys, static_cast<int>(l))) k += (k.empty() ? "" : ",") + key;
    lobe_keys.push_back(k);
  }
  f.set_attr("/" + g, "lobe_fit_status", joined(status));
  f.set_attr("/" + g, "lobe_fit_keys", joined(lobe_keys));
  f.set_attr("/" + g, "lobe_fit_lines", joined(lines));
  const h5::Dims FLd{s.F, s.L}, FLP{s.F, s.L, P};
  const std::string key_unit = "the key's unit (degrees for angles)";
  put(f, g + "/lobe_fitted", FLd, fitted, "fiber,lobe", "0/1", "1: the lobe was fitted alone (fit.per_lobe); 0 also where no free parameter acts on "
      "the lobe (its lobe_fit_lines entry says so)");
  put(f, g + "/lobe_fit_converged", FLd, fits.converged, "fiber,lobe", "0/1", "1: the lobe's own fit converged");
  put(f, g + "/model_energy_lobe_fit", s.dims(), energy, kAtlasDims, "fraction of incident light",
      "the model's lobe energy with that lobe's own fitted parameters (NaN: not fitted lobe by lobe)");
  put(f, g + "/chi2_lobe_fit", s.dims(), chi2, kAtlasDims, "",
      "chi-square of the bins with that lobe's own fitted parameters");
  put(f, g + "/dof_lobe_fit", s.dims(), dof, kAtlasDims, "", "its degrees of freedom");
  put(f, g + "/lobe_fit_start", FLP, fits.start, "fiber,lobe,fit_key", key_unit,
      "start of each key of the lobe's fit (attribute lobe_fit_keys, one line per lobe; empty when no lobe "
      "was fitted): the joint fit's value");
  put(f, g + "/lobe_fit_value", FLP, fits.value, "fiber,lobe,fit_key", key_unit, "fitted value of the lobe's own fit");
  put(f, g + "/lobe_fit_error", FLP, fits.error, "fiber,lobe,fit_key", key_unit,
      "standard error scaled by sqrt(max(1, chi2/dof)) (compare/fit.h)");
  put(f, g + "/lobe_fit_error_unscaled", FLP, fits.unscaled, "fiber,lobe,fit_key", key_unit, "sqrt(diag((J^T W J)^-1))");
  put(f, g + "/lobe_fit_at_bound", FLP, fits.bound, "fiber,lobe,fit_key", "0/1",
      "1: the value sits on an end of the table's range");
  put(f, g + "/lobe_fit_chi2_start", FLd, fits.chi2_start, "fiber,lobe", "",
      "the lobe fit's chi-square at its start (the lobe's bins, every theta_i)");
  put(f, g + "/lobe_fit_chi2", FLd, fits.chi2, "fiber,lobe", "", "the lobe fit's chi-square at the minimum");
  put(f, g + "/lobe_fit_dof", FLd, fits.dof, "fiber,lobe", "", "residuals minus fitted parameters");
  put(f, g + "/lobe_fit_iterations", FLd, fits.iterations, "fiber,lobe", "", "Levenberg-Marquardt iterations");
}

void write_model(h5::File& f, const Shape& s, const AtlasConfig& config, const std::vector<AtlasFiberResult>& fibers,
                 std::size_t m) {
  const std::string& name = config.models[m];
  const std::string g = "models/" + name;
  f.create_group(g);
  std::vector<std::string> keys;
  for (const auto& r : fibers)
    if (r.models[m].fitted) {
      keys = r.models[m].fit.keys;
      break;
    }
  const hsize_t P = keys.size();
  const std::size_t n = s.F * s.K * s.L * s.C;
  std::vector<double> eb(n, kNaN), ea(n, kNaN), cb(n, kNaN), ca(n, kNaN), db(n, kNaN), da(n, kNaN), judged(n, kNaN);
  std::vector<double> seconds(s.F, kNaN);
  FitColumns fits(s.F, P);
  std::vector<std::uint64_t> applicable(s.F, 0), fitted(s.F, 0);
  std::vector<std::string> status, before, after;
  for (std::size_t i = 0; i < fibers.size(); ++i) {
    const AtlasModelResult& r = fibers[i].models[m];
    status.push_back(r.status);
    before.push_back(r.params_before);
    after.push_back(r.params_after);
    applicable[i] = r.applicable;
    fitted[i] = r.fitted;
    seconds[i] = r.seconds;
    auto fill = [&](const std::vector<LobeComparison>& list, std::vector<double>& energy, std::vector<double>& c2,
                    std::vector<double>& d, bool mark_judged) {
      for (const LobeComparison& c : list) {
        const std::size_t at = s.at(i, c.k, c.lobe, c.channel);
        energy[at] = c.model_energy;
        c2[at] = c.bins.chi2;
        d[at] = c.bins.dof;
        if (mark_judged) judged[at] = c.judged ? 1.0 : 0.0;
      }
    };
    fill(r.before, eb, cb, db, true);
    fill(r.after, ea, ca, da, false);
    if (r.fitted) fits.set(i, r.fit);
  }
  std::string key_text;
  for (const auto& k : keys) key_text += (key_text.empty() ? "" : ",") + k;
  f.set_attr("/" + g, "fit_keys", key_text);
  f.set_attr("/" + g, "status", joined(status));
  f.set_attr("/" + g, "params_before", joined(before));
  f.set_attr("/" + g, "params_after", joined(after));
  const h5::Dims F{s.F}, FP{s.F, P};
  const std::string energy = "fraction of incident light", key_unit = "the key's unit (degrees for angles)";
  put(f, g + "/applicable", F, applicable, "fiber", "0/1", "1: the model accepted the fiber (status says why not)");
  put(f, g + "/fitted", F, fitted, "fiber", "0/1", "1: the free parameters were fitted");
  put(f, g + "/converged", F, fits.converged, "fiber", "0/1", "1: the fit converged");
  put(f, g + "/seconds", F, seconds, "fiber", "seconds", "wall time of this model's comparison and fit");
  put(f, g + "/model_energy_before", s.dims(), eb, kAtlasDims, energy,
      "the model's lobe energy with its physical defaults (NaN: not applicable)");
  put(f, g + "/model_energy_after", s.dims(), ea, kAtlasDims, energy,
      "the model's lobe energy with the fitted parameters (NaN: not fitted)");
  put(f, g + "/chi2_before", s.dims(), cb, kAtlasDims, "",
      "chi-square of the bins (compare/comparison.h), physical defaults");
  put(f, g + "/dof_before", s.dims(), db, kAtlasDims, "", "its degrees of freedom");
  put(f, g + "/chi2_after", s.dims(), ca, kAtlasDims, "", "chi-square of the bins with the fitted parameters");
  put(f, g + "/dof_after", s.dims(), da, kAtlasDims, "", "its degrees of freedom");
  put(f, g + "/judged", s.dims(), judged, kAtlasDims, "0/1", "1: the lobe has enough energy to be judged");
  put(f, g + "/fit_start", FP, fits.start, "fiber,fit_key", key_unit, "start value of each fit key (attribute fit_keys)");
  put(f, g + "/fit_value", FP, fits.value, "fiber,fit_key", key_unit, "fitted value");
  put(f, g + "/fit_error", FP, fits.error, "fiber,fit_key", key_unit,
      "standard error scaled by sqrt(max(1, chi2/dof)) (compare/fit.h)");
  put(f, g + "/fit_error_unscaled", FP, fits.unscaled, "fiber,fit_key", key_unit, "sqrt(diag((J^T W J)^-1))");
  put(f, g + "/fit_at_bound", FP, fits.bound, "fiber,fit_key", "0/1", "1: the value sits on an end of the table's range");
  put(f, g + "/fit_chi2_start", F, fits.chi2_start, "fiber", "", "the fit's chi-square at its start (all theta_i, lobes)");
  put(f, g + "/fit_chi2", F, fits.chi2, "fiber", "", "the fit's chi-square at the minimum");
  put(f, g + "/fit_dof", F, fits.dof, "fiber", "", "residuals minus fitted parameters");
  put(f, g + "/fit_iterations", F, fits.iterations, "fiber", "", "Levenberg-Marquardt iterations");
  if (config.per_lobe) write_lobe_fits(f, s, g, registered_model(config, name), keys, fibers, m);
}

}  // namespace

void write_atlas_axis_names(h5::File& f, const AtlasConfig& config) {
  // A fiber with a medulla has one lobe more, `scattered` (docs/FUR.md): the
  // file's lobe axis is the longest, NaN where a fiber has no such lobe.
  int channels = 0;
  bool from_melanin = true;
  for (const AtlasFiber& fiber : config.fibers) {
    channels = std::max(channels, static_cast<int>(fiber.settings.fiber.sigma_a.size()));
    from_melanin = from_melanin && fiber.settings.fiber.eumelanin.has_value();
  }
  write_axis_names(f, atlas_lobe_names(config.fibers), channels, from_melanin);
}

void write_atlas_file(const std::string& path, const AtlasConfig& config,
                      const std::vector<AtlasFiberResult>& fibers) {
  if (fibers.empty()) throw Error("atlas: no fiber was simulated");
  // The longest lobe axis and the most channels of any fiber (a medulla adds
  // the lobe `scattered`; absorption entries may differ in channels).
  Shape s{fibers.size(), config.theta_i.size(), 1, 1};
  for (const auto& r : fibers) {
    s.L = std::max<hsize_t>(s.L, r.lobes);
    s.C = std::max<hsize_t>(s.C, r.channels);
  }
  AtomicOutput out(path);
  {
    h5::File f = h5::File::create(out.temp_path());
    write_file_identity(f, "fiber-atlas", utc_timestamp());
    f.set_attr("/", "config_yaml", config.yaml);
    std::string models;
    for (const auto& m : config.models) models += (models.empty() ? "" : ",") + m;
    f.set_attr("/", "models", models);
    write_atlas_axis_names(f, config);
    put(f, "theta_i", {s.K}, config.theta_i, "incidence", "radians", "incident inclinations, the same for every fiber");
    write_fibers(f, s, fibers);
    f.create_group("models");
    for (std::size_t m = 0; m < config.models.size(); ++m) {
      write_model(f, s, config, fibers, m);
      // A variant's group says which registered model it runs, with what.
      if (const auto v = config.variant_of.find(config.models[m]); v != config.variant_of.end()) {
        const auto fixed = config.model_parameters.find(v->first);
        f.set_attr("/models/" + v->first, "model", v->second);
        std::string settings;
        if (fixed != config.model_parameters.end())
          for (const std::string& kv : fixed->second) settings += (settings.empty() ? "" : " ") + kv;
        f.set_attr("/models/" + v->first, "fixed_parameters", settings);
      }
      // fit.model_parameters: what the fit ran with beside what was judged
      // (the "before" and "after fit" columns: the model's defaults with
      // fixed_parameters; compare/atlas_config.h).
      if (const auto fit = config.fit_model_parameters.find(config.models[m]); fit != config.fit_model_parameters.end()) {
        const auto fixed = config.model_parameters.find(config.models[m]);
        const std::string g = "/models/" + config.models[m];
        f.set_attr(g, "fixed_parameters", fixed == config.model_parameters.end() ? "" : joined_settings(fixed->second));
        f.set_attr(g, "fit_only_parameters", joined_settings(fit->second));
      }
    }
    f.close();
  }
  out.commit();
}

namespace {

// fit.per_lobe's line under a model: how many lobe fits converged, and per
// lobe the median chi2/dof after the joint fit and after the lobe's own fit
// (over the fibers fitted lobe by lobe, the judged entries as the report's
// tables); or why none was made.
std::string describe_lobe_fits(const h5::File& f, const std::string& g, hsize_t F) {
  const h5::Dims dims = f.shape(g + "chi2_lobe_fit");
  if (dims.size() != 4 || dims[0] != F) throw Error(fmt::format("{}chi2_lobe_fit must be F x K x L x C", g));
  const hsize_t K = dims[1], L = dims[2], C = dims[3];
  const auto fitted = f.read_uint64s(g + "lobe_fitted", {F, L}, "fibers x lobes");
  const auto converged = f.read_uint64s(g + "lobe_fit_converged", {F, L}, "fibers x lobes");
  std::size_t n = 0, ok = 0;
  for (std::size_t i = 0; i < fitted.size(); ++i) {
    n += fitted[i] != 0;
    ok += fitted[i] != 0 && converged[i] != 0;
  }
  if (n == 0) {
    std::string status = f.attr_string(g, "lobe_fit_status");
    status = status.substr(0, status.find('\n'));
    return fmt::format("  per-lobe fit: none; {}{}\n", F > 1 ? "fiber 1: " : "", status);
  }
  const auto ca = f.read_doubles(g + "chi2_after", dims, ""), da = f.read_doubles(g + "dof_after", dims, "");
  const auto cl = f.read_doubles(g + "chi2_lobe_fit", dims, ""), dl = f.read_doubles(g + "dof_lobe_fit", dims, "");
  const auto judged = f.read_doubles(g + "judged", dims, "");
  const std::string names = f.attr_string("/", "lobe_names");
  std::vector<std::string> lobe_names;
  for (std::size_t a = 0; a <= names.size();) {
    const std::size_t b = std::min(names.find(',', a), names.size());
    lobe_names.push_back(names.substr(a, b - a));
    a = b + 1;
  }
  std::string s = fmt::format("  per-lobe fit: {} lobe fits, {} converged; median chi2/dof after joint fit -> "
                              "after per-lobe fit:", n, ok);
  for (hsize_t l = 0; l < L; ++l) {
    std::vector<double> joint, own;
    for (hsize_t i = 0; i < F; ++i) {
      if (!fitted[i * L + l]) continue;
      double c1 = 0, d1 = 0, c2 = 0, d2 = 0;
      for (hsize_t k = 0; k < K; ++k)
        for (hsize_t c = 0; c < C; ++c) {
          const std::size_t at = ((i * K + k) * L + l) * C + c;
          if (judged[at] == 1.0 && std::isfinite(cl[at]) && std::isfinite(ca[at])) {
            c1 += ca[at];
            d1 += da[at];
            c2 += cl[at];
            d2 += dl[at];
          }
        }
      if (d1 > 0 && d2 > 0) {
        joint.push_back(c1 / d1);
        own.push_back(c2 / d2);
      }
    }
    if (joint.empty()) continue;
    auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    };
    s += fmt::format(" {} {:.3g} -> {:.3g};", l < lobe_names.size() ? lobe_names[l] : std::to_string(l),
                     median(joint), median(own));
  }
  s.back() = '\n';
  return s;
}

}  // namespace

std::string describe_atlas_file(const std::string& path) {
  const h5::File f = h5::File::open_read(path);
  const h5::Dims F = f.shape("/fibers/photons");
  if (F.size() != 1) throw Error(fmt::format("{}: /fibers/photons must be one-dimensional (F fibers)", path));
  const h5::Dims K = f.shape("/theta_i");
  if (K.size() != 1) throw Error(fmt::format("{}: /theta_i must be one-dimensional (K directions)", path));
  std::string theta;
  for (double t : f.read_doubles("/theta_i", K, "")) theta += fmt::format("{}{:g}", theta.empty() ? "" : ", ", rad_to_deg(t));
  std::string s = fmt::format("{}: fiberlab atlas (software {}, created {})\n", path,
                              f.attr_string("/", "software_version"), f.attr_string("/", "created_utc"));
  s += fmt::format("{} fibers x {} incident direction(s) (theta_i {} deg), lobes {}, channels {}\n", F[0], K[0],
                   theta, f.attr_string("/", "lobe_names"), f.attr_string("/", "channel_names"));
  const auto count = [&](const std::string& name) {
    std::size_t n = 0;
    for (std::uint64_t v : f.read_uint64s(name, F, "fibers")) n += v != 0;
    return n;
  };
  std::string models = f.attr_string("/", "models");
  for (std::size_t start = 0; start < models.size();) {
    const std::size_t comma = std::min(models.find(',', start), models.size());
    const std::string m = models.substr(start, comma - start), g = "/models/" + m + "/";
    const std::string variant = f.has_attr(g, "model") ? fmt::format(" ({} {})", f.attr_string(g, "model"),
                                                                       f.attr_string(g, "fixed_parameters"))
                                                       : "";
    s += fmt::format("model {}{}: applicable to {}, fitted to {}, converged on {} of {} fibers\n", m, variant,
                     count(g + "applicable"), count(g + "fitted"), count(g + "converged"), F[0]);
    if (f.has_attr(g, "fit_only_parameters"))
      s += fmt::format("  fitted with {} on top of its fixed parameters; judged without them ({})\n",
                       f.attr_string(g, "fit_only_parameters"),
                       f.attr_string(g, "fixed_parameters").empty() ? "the model's defaults"
                                                                    : f.attr_string(g, "fixed_parameters"));
    if (f.has_attr(g, "lobe_fit_status")) s += describe_lobe_fits(f, g, F[0]);
    start = comma + 1;
  }
  return s;
}

}  // namespace fiberlab::compare
