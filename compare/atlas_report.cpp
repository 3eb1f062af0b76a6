#include "compare/atlas_report.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "compare/report.h"
#include "compare/report_folder.h"

namespace fiberlab::compare {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string num(double x, const char* spec = "{:.3g}") {
  return std::isfinite(x) ? fmt::format(fmt::runtime(spec), x) : std::string("-");
}

double per_dof(double chi2, int dof) { return dof > 0 ? chi2 / dof : std::nan(""); }

std::string fitted_params(const AtlasModelResult& m) {
  if (!m.fitted || m.fit.outcome == FitOutcome::NotFitted) return m.status;
  std::string s;
  for (std::size_t j = 0; j < m.fit.keys.size(); ++j)
    s += fmt::format("{}{} = {:.4g} ± {:.2g}{}", j ? ", " : "", m.fit.keys[j], m.fit.value[j], m.fit.error[j],
                     m.fit.at_bound[j] ? " (at bound)" : "");
  if (m.fit.outcome == FitOutcome::NotConverged) s += " (not converged)";
  return s;
}

// The longest lobe axis of any fiber (a medulla adds the lobe `scattered`).
int lobe_count(const std::vector<AtlasFiberResult>& fibers) {
  int L = 0;
  for (const AtlasFiberResult& f : fibers) L = std::max(L, f.lobes);
  return L;
}

// The name of lobe l on the atlas's lobe axis (atlas_lobe_names: the last is
// `scattered` when a fiber has a medulla, docs/FUR.md).
std::string lobe_label(int l, const std::vector<AtlasFiberResult>& fibers) {
  std::vector<AtlasFiber> of;
  for (const AtlasFiberResult& f : fibers) of.push_back(f.fiber);
  return atlas_lobe_names(of).at(static_cast<std::size_t>(l));
}

// The config's model_parameters, one sentence (empty when there are none).
std::string fixed_parameters(const AtlasConfig& config) {
  std::string s;
  for (const auto& [model, settings] : config.model_parameters) {
    const auto variant = config.variant_of.find(model);
    s += fmt::format("{}{}{}:", s.empty() ? config.variant_of.empty()
                                              ? " Fixed model parameters (not fitted; the config's model_parameters): "
                                              : " Fixed model parameters (not fitted; the config's model_parameters "
                                                "and variants): "
                                          : "; ",
                     model, variant == config.variant_of.end() ? "" : " (" + variant->second + ")");
    for (const std::string& kv : settings) s += " " + kv;
  }
  s = s.empty() ? s : s + ".";
  // fit.model_parameters: the fits ran with these; everything judged did not.
  std::string fit;
  for (const auto& [entry, settings] : config.fit_model_parameters) {
    fit += fmt::format("{}{}:", fit.empty() ? "" : "; ", entry);
    for (const std::string& kv : settings) fit += " " + kv;
  }
  if (!fit.empty())
    s += " Fitted with (fit.model_parameters, on top of the above while fitting only; the before and after "
         "columns and every chi-square are computed without them): " + fit + ".";
  return s;
}

// report_data.h5 (what scripts/plot_atlas.py reads) is the atlas file
// itself, copied byte for byte, not written a second time.
void copy_atlas_file(const std::string& atlas_path, const std::string& dir) {
  AtomicOutput out((std::filesystem::path(dir) / "report_data.h5").string());
  std::error_code ec;
  std::filesystem::copy_file(atlas_path, out.temp_path(), std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) throw Error(fmt::format("cannot copy {} to {}: {}", atlas_path, out.target(), ec.message()));
  out.commit();
}

// fit.per_lobe: each lobe's own fitted values, or why the model was not
// fitted lobe by lobe.
std::string lobe_fitted_params(const AtlasModelResult& m, const std::vector<AtlasFiberResult>& fibers) {
  if (m.lobe_fits.empty()) return m.lobe_fit_status;
  std::string s;
  for (std::size_t i = 0; i < m.lobe_fits.size(); ++i) {
    const LobeFit& lf = m.lobe_fits[i];
    s += fmt::format("{}{}:", s.empty() ? "" : "; ", lobe_label(lf.lobe, fibers));
    if (lf.fit.outcome == FitOutcome::NotFitted) {  // its status line says why ("not fitted: ...")
      s += " " + m.lobe_fit_lines.at(i);
      continue;
    }
    for (std::size_t j = 0; j < lf.fit.keys.size(); ++j)
      s += fmt::format(" {} = {:.4g} ± {:.2g}{}", lf.fit.keys[j], lf.fit.value[j], lf.fit.error[j],
                       lf.fit.at_bound[j] ? " (at bound)" : "");
    if (lf.fit.outcome == FitOutcome::NotConverged) s += " (not converged)";
  }
  return s;
}

}  // namespace

// Per model and lobe, medians over the fibers; with fit.per_lobe also the
// columns of the lobes' own fits beside the joint fit's.
std::string atlas_headline_markdown(const AtlasConfig& config, const std::vector<AtlasFiberResult>& fibers) {
  const bool lobe_fits = config.per_lobe;
  const int L = lobe_count(fibers);
  std::string s = lobe_fits ? "| model | fibers | lobe | median max\\|ΔE\\| before | after joint fit | after per-lobe fit | "
                              "median χ²/dof before | after joint fit | after per-lobe fit |\n"
                              "|---|---|---|---|---|---|---|---|---|\n"
                            : "| model | fibers | lobe | median max\\|ΔE\\| before | after fit | median χ²/dof before | "
                              "after fit |\n"
                              "|---|---|---|---|---|---|---|\n";
  for (std::size_t m = 0; m < config.models.size(); ++m)
    for (int l = 0; l < L; ++l) {
      std::vector<double> eb, ea, el, cb, ca, cl;
      int applicable = 0;
      for (const auto& f : fibers) {
        const AtlasModelResult& r = f.models[m];
        if (!r.applicable) continue;
        ++applicable;
        const AtlasLobeSummary sum = summarize_lobe(r, l);
        eb.push_back(sum.max_abs_energy_error);
        if (r.fitted) ea.push_back(sum.max_abs_energy_error_after);
        if (sum.lobe_fitted) el.push_back(sum.max_abs_energy_error_lobe_fit);
        if (sum.dof_before > 0) cb.push_back(per_dof(sum.chi2_before, sum.dof_before));
        if (r.fitted && sum.dof_after > 0) ca.push_back(per_dof(sum.chi2_after, sum.dof_after));
        if (sum.lobe_fitted && sum.dof_lobe_fit > 0) cl.push_back(per_dof(sum.chi2_lobe_fit, sum.dof_lobe_fit));
      }
      s += fmt::format("| {} | {} | {} | {} | {} |", config.models[m], applicable, lobe_label(l, fibers),
                       num(median(eb), "{:.4f}"), num(median(ea), "{:.4f}"));
      if (lobe_fits) s += fmt::format(" {} |", num(median(el), "{:.4f}"));
      s += fmt::format(" {} | {} |", num(median(cb)), num(median(ca)));
      if (lobe_fits) s += fmt::format(" {} |", num(median(cl)));
      s += "\n";
    }
  return s;
}

std::string atlas_table_markdown(const AtlasConfig& config, const std::vector<AtlasFiberResult>& fibers) {
  const int L = lobe_count(fibers);
  std::string s = "| fiber | model | fitted parameters (or why not) |";
  std::string rule = "|---|---|---|";
  if (config.per_lobe) {
    s += " per-lobe fit (or why not) |";
    rule += "---|";
  }
  for (int l = 0; l < L; ++l) {
    s += fmt::format(" {}: max\\|ΔE\\| | {}: χ²/dof |", lobe_label(l, fibers), lobe_label(l, fibers));
    rule += "---|---|";
  }
  s += "\n" + rule + "\n";
  for (std::size_t i = 0; i < fibers.size(); ++i)
    for (std::size_t m = 0; m < config.models.size(); ++m) {
      const AtlasModelResult& r = fibers[i].models[m];
      s += fmt::format("| {}. {} | {} | {} |", i + 1, fibers[i].fiber.label, r.model, fitted_params(r));
      if (config.per_lobe) s += fmt::format(" {} |", r.applicable ? lobe_fitted_params(r, fibers) : "-");
      for (int l = 0; l < L; ++l) {
        if (!r.applicable) {
          s += " - | - |";
          continue;
        }
        const AtlasLobeSummary sum = summarize_lobe(r, l);
        if (sum.lobe_fitted)
          s += fmt::format(" {} → {} → {} | {} → {} → {} |", num(sum.max_abs_energy_error, "{:.4f}"),
                           num(sum.max_abs_energy_error_after, "{:.4f}"),
                           num(sum.max_abs_energy_error_lobe_fit, "{:.4f}"), num(per_dof(sum.chi2_before, sum.dof_before)),
                           num(per_dof(sum.chi2_after, sum.dof_after)), num(per_dof(sum.chi2_lobe_fit, sum.dof_lobe_fit)));
        else if (r.fitted)
          s += fmt::format(" {} → {} | {} → {} |", num(sum.max_abs_energy_error, "{:.4f}"),
                           num(sum.max_abs_energy_error_after, "{:.4f}"), num(per_dof(sum.chi2_before, sum.dof_before)),
                           num(per_dof(sum.chi2_after, sum.dof_after)));
        else
          s += fmt::format(" {} | {} |", num(sum.max_abs_energy_error, "{:.4f}"),
                           num(per_dof(sum.chi2_before, sum.dof_before)));
      }
      s += "\n";
    }
  return s;
}

namespace {

// Every file of the report into the folder's staging folder, then moved into place.
std::string write_staged(ReportFolder& folder, const std::string& dir, const std::string& atlas_path,
                         const AtlasConfig& config, const std::vector<AtlasFiberResult>& fibers,
                         const std::string& command) {
  const std::string& staged = folder.staging();
  copy_atlas_file(atlas_path, staged);
  double sim_s = 0.0, fit_s = 0.0;
  for (const auto& f : fibers) {
    sim_s += f.sim_seconds;
    fit_s += f.fit_seconds;
  }
  const std::string headline = atlas_headline_markdown(config, fibers);
  const std::string table = atlas_table_markdown(config, fibers);
  std::string md = fmt::format(
      "# fiberlab atlas: {}\n\nCommand: `{}`. Data: `{}` (format fiber-atlas, docs/FILE_FORMAT.md).\n\n"
      "{} fibers x {} incident directions, {} photons per fiber and direction; simulation {:.0f} s, "
      "comparisons and fits {:.0f} s ({:.1f} s per fiber).\n\n"
      "ΔE: |E_model - E_sim| of a lobe (fraction of the incident light), the largest over theta_i and "
      "channels. χ²/dof: the bins' chi-square (compare/comparison.h) summed over theta_i and channels. "
      "\"before\": the model's physical defaults for the fiber; \"after\": its free parameters fitted jointly "
      "over every theta_i (compare/fit.h).{}{}\n\n## Per model and lobe (median over fibers)\n\n{}\n"
      "## Per fiber\n\n{}\n",
      config.path, command, atlas_path, fibers.size(), config.theta_i.size(),
      fibers.empty() ? 0 : fibers[0].photons, sim_s, fit_s,
      fibers.empty() ? 0.0 : (sim_s + fit_s) / fibers.size(),
      config.per_lobe ? " \"after per-lobe fit\": each lobe fitted alone from the joint fit's values, its own "
                        "width and shift (fit.per_lobe; compare/atlas.h); per fiber, the lobe's cells read "
                        "before → after joint fit → after per-lobe fit."
                      : "",
      fixed_parameters(config), headline, table);
  // The tables for the page (scripts/plot_atlas.py turns them into HTML).
  write_text(staged, "atlas_tables.md",
             "## Per model and lobe (median over fibers)\n\n" + headline + "\n## Per fiber\n\n" + table);
  const PlotOutcome plots = make_plots("atlas", staged);
  if (!plots.pngs.empty()) {
    md += "## Figures\n\n";
    for (const auto& png : plots.pngs) md += fmt::format("![{}]({})\n\n", png, png);
  }
  if (!plots.ran) md += plots.message + "\n";
  write_text(staged, "report.md", md);
  folder.commit();
  return fmt::format("report: {}/report.md{}{}\n", dir, plots.html ? ", " + dir + "/report.html" : "",
                     plots.ran ? "" : " (" + plots.message + ")");
}

}  // namespace

std::string write_atlas_report(const std::string& dir, const std::string& atlas_path, const AtlasConfig& config,
                               const std::vector<AtlasFiberResult>& fibers, const std::string& command) {
  ReportFolder folder(dir);
  try {
    return write_staged(folder, dir, atlas_path, config, fibers, command);
  } catch (const std::exception& e) {
    folder.rethrow(e);
  }
}

}  // namespace fiberlab::compare
