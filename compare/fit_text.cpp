#include "compare/fit_text.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "common/units.h"
#include "compare/report.h"
#include "compare/verdict_tables.h"

namespace fiberlab::compare {

namespace {

std::string unit_of(const std::string& key) {
  for (const char* angle : {"beta_long", "beta_azim", "alpha", "scale_tilt", "w_c"})
    if (key.rfind(angle, 0) == 0) return "deg";
  return key.rfind("sigma_a", 0) == 0 ? "1/R" : "";
}

}  // namespace

std::string fit_text(const FitResult& fr, const Verdict& before, const Verdict& after, const std::vector<std::string>& lobe_names) {
  if (fr.outcome == FitOutcome::NotFitted) {
    std::string s = fmt::format("\nnot fitted: {} ({} residuals, {} model evaluations)\n  chi2/dof {:.4f} (dof {})\n",
                                fr.stop_reason, fr.residuals, fr.evaluations, fr.per_dof(), fr.dof);
    for (std::size_t i = 0; i < fr.keys.size(); ++i)
      s += fmt::format("  {:<14} {:12.6g} {} (its start; not fitted)\n", fr.keys[i], fr.value[i], unit_of(fr.keys[i]));
    s += "  chi2/dof per lobe (unchanged):\n";
    for (const auto& b : before.rows)
      if (b.judged)
        s += fmt::format("  theta_i {:7.2f} phi_i {:>7} {:>5} c{}: {:10.3f}\n", rad_to_deg(b.theta_i), phi_text(b.phi_i),
                         lobe_names.at(static_cast<std::size_t>(b.lobe)), b.channel, b.bins.per_dof());
    return s;
  }
  std::string s = fmt::format("\nfit ({} residuals, {} iterations, {} model evaluations, {}: {}):\n",
                              fr.residuals, fr.iterations, fr.evaluations, outcome_name(fr.outcome),
                              fr.stop_reason);
  s += fmt::format("  chi2/dof {:.4f} -> {:.4f} (dof {}); errors scaled by sqrt(max(1, chi2/dof)) = {:.3f}\n",
                   fr.chi2_start / fr.dof, fr.per_dof(), fr.dof, std::sqrt(std::max(1.0, fr.per_dof())));
  for (std::size_t i = 0; i < fr.keys.size(); ++i)
    s += fmt::format("  {:<14} {:12.6g} -> {:12.6g} +- {:.3g} {} (unscaled {:.3g})\n", fr.keys[i], fr.start[i],
                     fr.value[i], fr.error[i], unit_of(fr.keys[i]), fr.error_unscaled[i]);
  s += "  chi2/dof per lobe, before -> after:\n";
  for (std::size_t i = 0; i < before.rows.size() && i < after.rows.size(); ++i) {
    const auto& b = before.rows[i];
    if (!b.judged) continue;
    s += fmt::format("  theta_i {:7.2f} phi_i {:>7} {:>5} c{}: {:10.3f} -> {:10.3f}\n", rad_to_deg(b.theta_i),
                     phi_text(b.phi_i), lobe_names.at(static_cast<std::size_t>(b.lobe)), b.channel, b.bins.per_dof(),
                     after.rows[i].bins.per_dof());
  }
  return s;
}

std::string fit_markdown(const FitResult& fr, const Verdict& before, const Verdict& after, const std::vector<std::string>& lobe_names) {
  if (fr.outcome == FitOutcome::NotFitted) {
    std::string md = fmt::format("## Fit\n\nNot fitted: {} (chi2/dof {:.4f} over {} dof).\n\n"
                                 "| key | value (its start) |\n|---|---|\n",
                                 fr.stop_reason, fr.per_dof(), fr.dof);
    for (std::size_t i = 0; i < fr.keys.size(); ++i) md += fmt::format("| {} | {:.6g} |\n", fr.keys[i], fr.value[i]);
    md += "\n| theta_i | phi_i | lobe | channel | chi2/dof (unchanged) |\n|---|---|---|---|---|\n";
    for (const auto& b : before.rows)
      if (b.judged)
        md += fmt::format("| {:.2f} | {} | {} | {} | {:.3f} |\n", rad_to_deg(b.theta_i), phi_text(b.phi_i),
                          lobe_names.at(static_cast<std::size_t>(b.lobe)), b.channel, b.bins.per_dof());
    return md;
  }
  std::string md = fmt::format("## Fit\n\nchi2/dof {:.4f} -> {:.4f} over {} dof ({} iterations; {}: {}).\n\n"
                               "| key | start | fitted | error | unscaled error |\n|---|---|---|---|---|\n",
                               fr.chi2_start / fr.dof, fr.per_dof(), fr.dof, fr.iterations,
                               outcome_name(fr.outcome), fr.stop_reason);
  for (std::size_t i = 0; i < fr.keys.size(); ++i)
    md += fmt::format("| {} | {:.6g} | {:.6g} | {:.3g} | {:.3g} |\n", fr.keys[i], fr.start[i], fr.value[i],
                      fr.error[i], fr.error_unscaled[i]);
  md += "\n| theta_i | phi_i | lobe | channel | chi2/dof before | after |\n|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < before.rows.size() && i < after.rows.size(); ++i) {
    const auto& b = before.rows[i];
    if (!b.judged) continue;
    md += fmt::format("| {:.2f} | {} | {} | {} | {:.3f} | {:.3f} |\n", rad_to_deg(b.theta_i), phi_text(b.phi_i),
                      lobe_names.at(static_cast<std::size_t>(b.lobe)), b.channel, b.bins.per_dof(), after.rows[i].bins.per_dof());
  }
  return md;
}

std::string fit_json(const FitResult& fr, const Verdict& before, const Verdict& after,
                     const std::vector<std::string>& fit_only_settings) {
  std::string items, per_lobe;
  for (std::size_t i = 0; i < fr.keys.size(); ++i)
    items += fmt::format("{}{{\"key\": {}, \"start\": {}, \"value\": {}, \"error\": {}, \"error_unscaled\": {}}}",
                         i ? ", " : "", json_string(fr.keys[i]), json_number(fr.start[i]), json_number(fr.value[i]),
                         json_number(fr.error[i]), json_number(fr.error_unscaled[i]));
  for (std::size_t i = 0; i < before.rows.size() && i < after.rows.size(); ++i) {
    const auto& b = before.rows[i];
    per_lobe += fmt::format("{}{{\"theta_i_deg\": {}, \"phi_i_deg\": {}, \"lobe\": {}, \"channel\": {}, "
                            "\"chi2_per_dof_before\": {}, \"chi2_per_dof_after\": {}}}",
                            i ? ", " : "", json_number(rad_to_deg(b.theta_i)), json_number(rad_to_deg(b.phi_i)),
                            b.lobe, b.channel, json_number(b.bins.per_dof()),
                            json_number(after.rows[i].bins.per_dof()));
  }
  std::string settings;
  for (const std::string& s : fit_only_settings) settings += (settings.empty() ? "" : ", ") + json_string(s);
  return fmt::format(
      "{{\"parameters\": [{}], \"chi2_start\": {}, \"chi2\": {}, \"dof\": {}, \"iterations\": {}, "
      "\"converged\": {}, \"outcome\": {}, \"stop_reason\": {}, \"error_scale\": \"sqrt(max(1, chi2/dof))\", "
      "\"fit_only_settings\": [{}], \"per_lobe\": [{}]}}",
      items, json_number(fr.chi2_start), json_number(fr.chi2), fr.dof, fr.iterations,
      fr.converged ? "true" : "false", json_string(outcome_name(fr.outcome)), json_string(fr.stop_reason),
      settings, per_lobe);
}

}  // namespace fiberlab::compare
