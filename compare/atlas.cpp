#include "compare/atlas.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "analytic/model_registry.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/interrupt.h"
#include "compare/fit_settings.h"
#include "compare/models.h"
#include "sim/store/result_file.h"
#include "sim/run/simulation.h"

namespace fiberlab::compare {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void check_interrupt() {
  if (interrupt_requested()) throw AtlasInterrupted{interrupt_signal()};
}

void say(const AtlasControl& c, const std::string& line) {
  if (c.progress) c.progress(line);
}

sim::ResultFile simulate(const sim::Settings& s, const AtlasControl& control) {
  const sim::Simulation simulation(s);
  sim::RunProgress state = simulation.start();
  sim::RunControl rc;
  rc.threads = control.threads;
  if (control.progress) {
    auto last = std::make_shared<Clock::time_point>(Clock::now());
    rc.progress = [last, &control](std::uint64_t done, std::uint64_t total) {
      if (seconds_since(*last) < 2.0 && done != total) return;
      *last = Clock::now();
      control.progress(fmt::format("  simulating: {} / {} photons", done, total));
    };
  }
  if (simulation.run(state, rc) == sim::RunOutcome::Interrupted) throw AtlasInterrupted{interrupt_signal()};
  return sim::make_result(s, simulation.grid(), state.tallies);
}

std::vector<LobeComparison> judge_model(const sim::ResultFile& r, const std::string& name,
                                        const analytic::ModelParameters& p) {
  const auto model = compare::make_model(name, p);
  return compare(r, predict_result(*model, r), analytic::theta_r_shifts(name, p));
}

// The parameters a fit starts from: the judged ones `p` with the entry's
// fit.model_parameters on top (compare/atlas_config.h), e.g. huang2022's
// cheaper quadrature. Those keys are fixed, so a fit moves only its own keys.
analytic::ModelParameters fit_start(const AtlasConfig& config, const std::string& entry, const std::string& model,
                                    const analytic::ModelParameters& p) {
  const auto settings = config.fit_model_parameters.find(entry);
  if (settings == config.fit_model_parameters.end()) return p;
  return with_fit_settings(model, p, settings->second);
}

// A fit's result judged: `judged` (the parameters without fit-only settings)
// with the fitted keys' values, so fit.params is what the "after" columns
// use (and what a resumed checkpoint rebuilds from its start, the same way).
// Without fit-only settings fit.params is left as the fit returned it.
void judge_with(const AtlasConfig& config, const std::string& entry, const std::string& model,
                const analytic::ModelParameters& judged, FitResult& fit) {
  if (config.fit_model_parameters.count(entry)) put_onto_judged(model, judged, fit);
}

// "fitted (converged: why)", "fitted (at a bound: key = value; why)",
// "fitted (not converged: why)" or "not fitted: why" (no key acts on the
// fitted bins): the per-fiber table's status.
std::string fit_status(const FitResult& fit) {
  if (fit.outcome == FitOutcome::NotFitted) return "not fitted: " + fit.stop_reason;
  std::string bound;
  for (std::size_t j = 0; j < fit.keys.size(); ++j)
    if (fit.at_bound[j]) bound += fmt::format("{}{} = {:.6g}", bound.empty() ? "" : ", ", fit.keys[j], fit.value[j]);
  if (fit.outcome == FitOutcome::AtBound) return fmt::format("fitted (at a bound: {}; {})", bound, fit.stop_reason);
  return fmt::format("fitted ({}: {})", outcome_name(fit.outcome), fit.stop_reason);
}

// The lobes of fit.lobes this fiber has (empty: every lobe). fit.lobes
// indexes the atlas's lobe axis, whose `scattered` only a medullated fiber
// has; the other lobes have the same index in every fiber (the tally is
// shared).
std::vector<int> fiber_fit_lobes(const AtlasConfig& config, const sim::ResultFile& r) {
  std::vector<int> out;
  for (int l : config.fit_lobes)
    if (l < r.lobes) out.push_back(l);
  return out;
}

// fit.per_lobe: whether the model has a per-lobe parameter among `keys`
// (compare/fit.h per_lobe_keys renames at least one key for some lobe).
bool has_per_lobe_keys(const std::string& model, const std::vector<std::string>& keys, int lobes) {
  for (int l = 0; l < lobes; ++l)
    if (per_lobe_keys(model, keys, l) != keys) return true;
  return false;
}

// fit.per_lobe: each lobe of the fit fitted alone from the joint fit's
// values (compare/atlas.h), and that lobe judged again with them.
void fit_lobe_by_lobe(const AtlasConfig& config, const sim::ResultFile& r, const std::string& model,
                      const std::string& name, const std::vector<std::string>& keys, AtlasModelResult& m,
                      const AtlasControl& control) {
  if (keys.empty()) {
    m.lobe_fit_status = "not fitted lobe by lobe: its parameter table marks no parameter free";
    return;
  }
  if (!m.fitted) {
    m.lobe_fit_status = "not fitted lobe by lobe: no joint fit to start from";
    return;
  }
  if (!has_per_lobe_keys(model, keys, r.lobes)) {
    std::string joined;
    for (const std::string& k : keys) joined += (joined.empty() ? "" : ", ") + k;
    m.lobe_fit_status = fmt::format("not fitted lobe by lobe: no per-lobe parameter (its free keys {} are "
                                    "shared by every lobe)", joined);
    say(control, fmt::format("  {}: {}", name, m.lobe_fit_status));
    return;
  }
  check_interrupt();
  try {
    Options fit_options;
    fit_options.lobes = fiber_fit_lobes(config, r);
    m.lobe_fits = fit_each_lobe(r, model, fit_start(config, name, model, m.fit.params), keys, fit_options,
                                config.max_iterations,
                                [&](const std::string& line) {
                                  check_interrupt();
                                  say(control, "  " + name + " per-lobe " + line);
                                });
  } catch (const Error& e) {
    m.lobe_fits.clear();
    m.lobe_fit_status = std::string("per-lobe fit failed: ") + e.what();
    say(control, fmt::format("  {}: {}", name, m.lobe_fit_status));
    return;
  }
  m.lobe_fit_status = "fitted lobe by lobe";
  for (LobeFit& lf : m.lobe_fits) {
    judge_with(config, name, model, m.fit.params, lf.fit);
    m.lobe_fit_lines.push_back(fit_status(lf.fit));
    for (const LobeComparison& c : judge_model(r, model, lf.fit.params))
      if (c.lobe == lf.lobe) m.after_lobe_fit.push_back(c);
    say(control, fmt::format("  {} {}: {}", name, r.lobe_names().at(static_cast<std::size_t>(lf.lobe)),
                             m.lobe_fit_lines.back()));
  }
}

AtlasModelResult evaluate_model(const AtlasConfig& config, const AtlasFiber& fiber, const sim::ResultFile& r,
                                const std::string& name, const AtlasControl& control) {
  const auto t0 = Clock::now();
  AtlasModelResult m;
  m.model = name;  // the entry's name; `model` is the registered model it runs
  const std::string& model = registered_model(config, name);
  analytic::ModelParameters p;
  try {
    p = atlas_start_params(config, fiber, name);
  } catch (const Error& e) {
    m.status = std::string("not applicable: ") + e.what();
    if (config.per_lobe) m.lobe_fit_status = "not fitted lobe by lobe: not applicable";
    say(control, fmt::format("  {}: {}", name, m.status));
    return m;
  }
  m.applicable = true;
  m.params_before = analytic::describe_params(model, p);
  m.before = judge_model(r, model, p);
  const std::vector<std::string> keys = free_fit_keys(model);
  if (keys.empty()) {
    m.status = "not fitted: its parameter table marks no parameter free";
  } else if (config.max_iterations == 0) {
    m.status = "not fitted: fit.max_iterations = 0";
  } else if (!config.fit_lobes.empty() && fiber_fit_lobes(config, r).empty()) {
    m.status = fmt::format("not fitted: fit.lobes names none of the fiber's lobes ({})", join_names(r.lobe_names()));
  } else {
    check_interrupt();
    try {
      Options fit_options;
      fit_options.lobes = fiber_fit_lobes(config, r);
      m.fit = fit_model(r, model, fit_start(config, name, model, p), keys, fit_options, config.max_iterations,
                        [&](const std::string& line) {
                          check_interrupt();
                          say(control, "  " + name + " " + line);
                        });
      judge_with(config, name, model, p, m.fit);
      m.fitted = true;
      m.status = fit_status(m.fit);
      m.params_after = analytic::describe_params(model, m.fit.params);
      m.after = judge_model(r, model, m.fit.params);
    } catch (const Error& e) {
      m.status = std::string("fit failed: ") + e.what();
    }
  }
  if (config.per_lobe) fit_lobe_by_lobe(config, r, model, name, keys, m, control);
  m.seconds = seconds_since(t0);
  say(control, fmt::format("  {}: {} ({:.1f} s)", name, m.status, m.seconds));
  return m;
}

}  // namespace

analytic::ModelParameters atlas_start_params(const AtlasConfig& config, const AtlasFiber& fiber,
                                         const std::string& entry) {
  const std::string& model = registered_model(config, entry);
  const auto fixed = config.model_parameters.find(entry);
  const analytic::ModelParameters p = params_for(
      fiber.settings,
      ModelSpec{model, fixed == config.model_parameters.end() ? std::vector<std::string>{} : fixed->second, entry},
      {});
  compare::make_model(model, p);  // the model's own checks
  return p;
}

AtlasFiberResult run_atlas_fiber(const AtlasConfig& config, std::size_t index, const AtlasControl& control) {
  check_interrupt();
  AtlasFiberResult out;
  out.fiber = config.fibers.at(index);
  say(control, fmt::format("fiber {} / {}: {}", index + 1, config.fibers.size(), out.fiber.label));
  const auto t0 = Clock::now();
  const sim::ResultFile r = simulate(out.fiber.settings, control);
  out.sim_seconds = seconds_since(t0);
  out.theta_i = r.theta_i;
  out.lobes = r.lobes;
  out.channels = r.channels;
  out.photons = r.photons.empty() ? 0 : r.photons[0];
  for (std::size_t k = 0; k < r.configs(); ++k)
    for (int l = 0; l < r.lobes; ++l)
      for (int c = 0; c < r.channels; ++c) {
        const sim::Estimate e = sim::lobe_energy(r, k, l, c);
        out.sim_energy.push_back(e.mean);
        out.sim_error.push_back(e.std_error);
      }
  say(control, fmt::format("  simulated in {:.1f} s", out.sim_seconds));
  const auto t1 = Clock::now();
  for (const std::string& name : config.models) {
    check_interrupt();
    out.models.push_back(evaluate_model(config, out.fiber, r, name, control));
  }
  out.fit_seconds = seconds_since(t1);
  return out;
}

AtlasLobeSummary summarize_lobe(const AtlasModelResult& m, int lobe) {
  AtlasLobeSummary s;
  auto add = [&](const std::vector<LobeComparison>& list, double& chi2, int& dof, double& max_abs, bool before) {
    for (const LobeComparison& c : list) {
      if (c.lobe != lobe) continue;
      const double err = std::fabs(c.model_energy - c.sim_energy);
      max_abs = std::max(max_abs, err);
      if (before && c.sim_energy > 0.0 && c.judged)
        s.max_rel_energy_error = std::max(s.max_rel_energy_error, err / c.sim_energy);
      if (!c.judged) continue;
      s.judged = true;
      chi2 += c.bins.chi2;
      dof += c.bins.dof;
    }
  };
  add(m.before, s.chi2_before, s.dof_before, s.max_abs_energy_error, true);
  add(m.after, s.chi2_after, s.dof_after, s.max_abs_energy_error_after, false);
  for (const LobeFit& lf : m.lobe_fits) s.lobe_fitted = s.lobe_fitted || lf.lobe == lobe;
  const bool judged = s.judged;  // judged before or after the joint fit, as above
  add(m.after_lobe_fit, s.chi2_lobe_fit, s.dof_lobe_fit, s.max_abs_energy_error_lobe_fit, false);
  s.judged = judged;
  return s;
}

}  // namespace fiberlab::compare
