// `fiberlab compare RESULT.h5 --model M [--set KEY=VALUE ...] [--fit KEYS]
//                  [--report DIR] [--max-chi2 X]`
// `fiberlab compare RESULT.h5 --prediction PRED.h5 [--report DIR] [--max-chi2 X]`
// Is model M (or any prediction file) right for the fiber of RESULT, where,
// and by how much? Exit status 0 when every judged lobe is accepted, 1 when
// one is not, 2 on bad input. The statistics: compare/comparison.h; the rule:
// compare/verdict.h; the prediction format: compare/prediction_file.h.
// The work: app/compare.h.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <chrono>
#include <memory>
#include <string>

#include "analytic/model_registry.h"
#include "app/compare.h"
#include "cli/commands.h"
#include "compare/compare_report.h"
#include "compare/comparison.h"
#include "compare/fit_text.h"
#include "compare/verdict_tables.h"

namespace fiberlab::cli {

namespace {

// Fit progress, one line per iteration, on stderr (fits take minutes).
void print_progress(const std::string& line) { fmt::print(stderr, "{}\n", line); }

// --per-lobe: each lobe's fit printed with its lobe's chi2/dof before and
// after; returned as markdown for the report. The verdict stays the joint fit's.
std::string per_lobe_fits(const app::Comparison& c, const compare::Verdict& before) {
  std::string md = "\n## Per-lobe fits\n";
  for (const app::LobeFitVerdict& lf : app::fit_each_lobe(c, before, print_progress)) {
    const std::vector<std::string> names = c.result.lobe_names();
    const std::string& name = names.at(static_cast<std::size_t>(lf.lobe));
    fmt::print("\nper-lobe fit of {}:", name);
    fmt::print("{}", compare::fit_text(lf.fit, lf.before, lf.after, names));
    md += fmt::format("\n### {}\n\n", name) + compare::fit_markdown(lf.fit, lf.before, lf.after, names);
  }
  return md;
}

void compare_command(const app::CompareRequest& o) {
  const app::Comparison c = app::set_up(o);
  const sim::ResultFile& result = c.result;

  const auto t0 = std::chrono::steady_clock::now();
  fmt::print("{}: {} incident direction(s), {} lobes, {} channel(s), {} x {} bins\n", o.result,
             result.configs(), result.lobes, result.channels, result.grid.n_theta(), result.grid.n_phi());
  app::Predicted current = c.from_file ? c.file_prediction : app::predicted_by_model(result, c.spec, c.params, c.fiber_notes);
  fmt::print("{}", current.header);
  compare::Verdict v = app::judge(c, current);
  fmt::print("{}", compare::verdict_table(v, result.lobe_names()));

  analytic::ModelParameters params = c.params;
  std::string fit_json = "null", fit_md;
  if (!c.fit_keys.empty()) {
    app::JointFit fit = app::fit_jointly(c, print_progress);
    params = fit.fit.params;
    current = std::move(fit.predicted);
    const compare::Verdict before = v;
    v = fit.after;
    fmt::print("{}", compare::fit_text(fit.fit, before, v, result.lobe_names()));
    if (!c.fit_settings.empty())
      fmt::print("  fitted with {} (--fit-set): the fit's chi2/dof line is at these; the per-lobe rows and the "
                 "verdict at the judged parameters\n",
                 fmt::join(c.fit_settings, " "));
    fit_md = compare::fit_markdown(fit.fit, before, v, result.lobe_names());
    if (!c.fit_settings.empty())
      fit_md += fmt::format("\nFitted with the fit-only settings {} (`--fit-set`): the chi2/dof line above is at "
                            "them, the per-lobe rows and the verdict at the judged parameters.\n",
                            fmt::join(c.fit_settings, " "));
    fit_json = compare::fit_json(fit.fit, before, v, c.fit_settings);
    fmt::print("\nafter the fit: {}", current.header);
    fmt::print("{}", compare::verdict_table(v, result.lobe_names()));
    if (o.per_lobe) fit_md += per_lobe_fits(c, before);
  }

  fmt::print("\n{} of {} judged lobes accepted ({}); {:.1f} s\n", v.judged - v.rejected, v.judged, v.criterion,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (v.judged == 0)
    fmt::print("no lobe was judged (each has energy below --min-energy = {:g} in both the result and "
               "the prediction, or no compared bins): nothing is accepted, exit status 1\n",
               o.min_energy);

  if (!o.report.empty()) {
    compare::CompareReport rep;
    rep.dir = o.report;
    rep.result_path = o.result;
    rep.label = current.label;
    rep.header = current.header;
    if (!c.from_file) rep.params_json = compare::params_json(c.spec.name, params);
    rep.fit_json = fit_json;
    rep.fit_markdown = fit_md;
    rep.plot_channel = o.channel;
    fmt::print("{}", compare::write_compare_report(rep, result, current.bins, v));
  }
  exit_code = v.all_accepted ? 0 : 1;
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto o = std::make_shared<fiberlab::app::CompareRequest>();
  auto max_chi2_value = std::make_shared<double>(0.0);
  CLI::App* cmd = app.add_subcommand(
      "compare", "Validate a model against a result's histograms (exit 0: every judged lobe accepted, "
                 "at least one judged; 1: a lobe rejected, or none judged; 2: bad input)");
  cmd->add_option("result", o->result, "Result file (.h5)")->required();
  cmd->add_option("--model", o->model,
                  fmt::format("{}, optionally NAME:KEY=VALUE:... (per-model --set)",
                              fmt::join(analytic::model_names(), " | ")));
  cmd->add_option("--prediction", o->prediction,
                  "Judge a prediction file instead of a built-in model (format fiber-prediction: "
                  "docs/FILE_FORMAT.md)");
  cmd->add_option("--set", o->settings,
                  "Model parameter KEY=VALUE (angles in degrees; repeatable; `fiberlab models` lists the keys)");
  cmd->add_option("--fit", o->fit,
                  "Comma-separated parameters to fit: the model's numeric keys (eta, beta_long, beta_m, ...), NAME[p] "
                  "for one lobe's entry (beta_long[0],alpha[2]), or the physical scale_tilt (shift rule)");
  cmd->add_option("--fit-lobes", o->fit_lobes,
                  "Comma-separated lobes the fit judges and fits (R,TT,TRT,p>=3 or indices; default every lobe)");
  cmd->add_option("--fit-set", o->fit_settings,
                  "Model parameter KEY=VALUE applied only while fitting (repeatable; e.g. huang2022's "
                  "quadrature_points=524288: fit cheaply, judge at --set's or the default quadrature)");
  cmd->add_flag("--per-lobe", o->per_lobe,
                "Also fit each lobe alone (its own beta_long[p], beta_azim[p], alpha[p] where the model has them), "
                "after the joint fit");
  cmd->add_option("--report", o->report, "Write a report folder (report.md, metrics.csv/json, PNG plots)");
  CLI::Option* max_chi2 = cmd->add_option("--max-chi2", *max_chi2_value,
                  "Accept a lobe when chi2/dof <= X, X > 0 (default: 1 + 5 sqrt(2/dof), five standard deviations)");
  cmd->add_option("--min-effective", o->min_effective, "Bins compared one by one need S1^2/S2 >= this (30)");
  cmd->add_option("--model-error", o->model_error,
                  "Relative error assumed for the model's bin integrals, in [0, 1] (1e-4)");
  cmd->add_option("--min-energy", o->min_energy,
                  "Lobes below this energy (both sides) are not judged, in [0, 1) (1e-4); when no lobe "
                  "is judged nothing is accepted (exit 1)");
  cmd->add_option("--channel", o->channel, "Channel shown in the plots (0)");
  // Built when --help asks for it, not at every start (about 0.3 ms each).
  cmd->footer([] { return "\nModel parameters (--set KEY=VALUE):\n\n" + analytic::models_listing(); });
  cmd->callback([o, max_chi2, max_chi2_value] {
    if (max_chi2->count() > 0) o->max_chi2 = *max_chi2_value;
    compare_command(*o);
  });
}

}  // namespace fiberlab::cli
