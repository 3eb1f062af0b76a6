#include "compare/verdict_tables.h"

#include <fmt/core.h>

#include <cmath>

#include "common/estimate_text.h"
#include "common/units.h"
#include "compare/report.h"

namespace fiberlab::compare {

std::string phi_text(double phi_i) {
  return std::isnan(phi_i) ? std::string("uniform") : fmt::format("{:.2f}", rad_to_deg(phi_i));
}

std::string incidence_label(double theta_i, double phi_i) {
  return fmt::format("theta_i {:.2f} deg, phi_i {}", rad_to_deg(theta_i),
                     std::isnan(phi_i) ? std::string("uniform") : phi_text(phi_i) + " deg");
}

namespace {
const char* verdict_word(const Verdict& v, std::size_t i) {
  return !v.rows[i].judged ? "not judged" : (v.accepted[i] ? "ok" : "REJECTED");
}
}  // namespace

std::string verdict_table(const Verdict& v, const std::vector<std::string>& lobe_names) {
  std::string s = fmt::format(
      "{:>7} {:>7} {:>5} {:>2} {:>21} {:>10} {:>7} {:>10} {:>5} {:>8} {:>8} {:>6} {:>8} {:>8} {:>8}  {}\n",
      "theta_i", "phi_i", "lobe", "c", "E_sim +- se", "E_model", "z", "chi2/dof", "dof", "theta", "phi", "L1",
      "cen_sim", "cen_mod", "shift", "verdict");
  for (std::size_t i = 0; i < v.rows.size(); ++i) {
    const auto& r = v.rows[i];
    s += fmt::format(
        "{:7.2f} {:>7} {:>5} {:>2} {:>21} {:10.6f} {:7.1f} {:10.3f} {:5d} {:8.3f} {:8.3f} {:6.3f} {:8.3f} "
        "{:8.3f} {:8.3f}  {}\n",
        rad_to_deg(r.theta_i), phi_text(r.phi_i), lobe_names.at(static_cast<std::size_t>(r.lobe)), r.channel,
        estimate_text(r.sim_energy, r.sim_error), r.model_energy, r.energy_z,
        r.bins.per_dof(), r.bins.dof, r.theta_marginal.per_dof(), r.phi_marginal.per_dof(), r.l1,
        rad_to_deg(r.centroid_sim), rad_to_deg(r.centroid_model), rad_to_deg(r.measured_shift),
        verdict_word(v, i));
  }
  return s;
}

std::string verdict_csv(const Verdict& v, const std::vector<std::string>& lobe_names) {
  std::string s =
      "theta_i_deg,phi_i_deg,lobe,lobe_name,channel,sim_energy,sim_error,model_energy,energy_z,chi2,dof,"
      "chi2_per_dof,compared_bins,rest_sim,rest_model,theta_chi2_per_dof,theta_dof,phi_chi2_per_dof,"
      "phi_dof,l1,peak_sim_deg,peak_model_deg,centroid_sim_deg,centroid_sim_error_deg,"
      "centroid_model_deg,alpha_model_deg,measured_shift_deg,judged,threshold,accepted\n";
  for (std::size_t i = 0; i < v.rows.size(); ++i) {
    const auto& r = v.rows[i];
    s += fmt::format("{:.6g},{:.6g},{},{},{},{:.9g},{:.3g},{:.9g},{:.4g},{:.6g},{},{:.6g},{},{:.6g},{:.6g},"
                     "{:.6g},{},{:.6g},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.4g},{:.6g},{:.6g},{:.6g},{},{:.4g},{}\n",
                     rad_to_deg(r.theta_i), rad_to_deg(r.phi_i), r.lobe, lobe_names.at(static_cast<std::size_t>(r.lobe)), r.channel,
                     r.sim_energy, r.sim_error, r.model_energy, r.energy_z, r.bins.chi2, r.bins.dof,
                     r.bins.per_dof(), r.compared_bins, r.rest_sim, r.rest_model, r.theta_marginal.per_dof(),
                     r.theta_marginal.dof, r.phi_marginal.per_dof(), r.phi_marginal.dof, r.l1,
                     rad_to_deg(r.peak_sim), rad_to_deg(r.peak_model), rad_to_deg(r.centroid_sim),
                     rad_to_deg(r.centroid_sim_error), rad_to_deg(r.centroid_model), rad_to_deg(r.alpha_model),
                     rad_to_deg(r.measured_shift), r.judged ? 1 : 0, v.threshold[i], v.accepted[i] ? 1 : 0);
  }
  return s;
}

std::string verdict_json_rows(const Verdict& v, const std::vector<std::string>& lobe_names) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.rows.size(); ++i) {
    const auto& r = v.rows[i];
    s += fmt::format(
        "{}\n    {{\"theta_i_deg\": {}, \"phi_i_deg\": {}, \"k\": {}, \"lobe\": {}, \"lobe_name\": \"{}\", "
        "\"channel\": {}, \"sim_energy\": {}, \"sim_error\": {}, \"model_energy\": {}, \"energy_z\": {}, "
        "\"chi2\": {}, \"dof\": {}, \"chi2_per_dof\": {}, \"theta_marginal_chi2_per_dof\": {}, "
        "\"theta_marginal_dof\": {}, \"phi_marginal_chi2_per_dof\": {}, \"phi_marginal_dof\": {}, "
        "\"l1\": {}, \"peak_sim_deg\": {}, \"peak_model_deg\": {}, \"centroid_sim_deg\": {}, "
        "\"centroid_sim_error_deg\": {}, \"centroid_model_deg\": {}, \"alpha_model_deg\": {}, "
        "\"measured_shift_deg\": {}, \"judged\": {}, \"threshold\": {}, \"accepted\": {}}}",
        i ? "," : "", json_number(rad_to_deg(r.theta_i)), json_number(rad_to_deg(r.phi_i)), r.k, r.lobe,
        lobe_names.at(static_cast<std::size_t>(r.lobe)), r.channel, json_number(r.sim_energy), json_number(r.sim_error),
        json_number(r.model_energy), json_number(r.energy_z), json_number(r.bins.chi2), r.bins.dof,
        json_number(r.bins.per_dof()), json_number(r.theta_marginal.per_dof()), r.theta_marginal.dof,
        json_number(r.phi_marginal.per_dof()), r.phi_marginal.dof, json_number(r.l1),
        json_number(rad_to_deg(r.peak_sim)), json_number(rad_to_deg(r.peak_model)),
        json_number(rad_to_deg(r.centroid_sim)), json_number(rad_to_deg(r.centroid_sim_error)),
        json_number(rad_to_deg(r.centroid_model)), json_number(rad_to_deg(r.alpha_model)),
        json_number(rad_to_deg(r.measured_shift)), r.judged ? "true" : "false", json_number(v.threshold[i]),
        v.accepted[i] ? "true" : "false");
  }
  return s + "\n  ]";
}

std::string verdict_markdown(const Verdict& v, const std::vector<std::string>& lobe_names) {
  std::string md =
      "| theta_i | phi_i | lobe | channel | E_sim +- se | E_model | chi2/dof (dof) | theta marg. | phi marg. | "
      "L1 | centroid sim / model (deg) | shift (deg) | verdict |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < v.rows.size(); ++i) {
    const auto& r = v.rows[i];
    md += fmt::format("| {:.2f} | {} | {} | {} | {} | {:.5f} | {:.3f} ({}) | {:.3f} | {:.3f} | "
                      "{:.3f} | {:.2f} / {:.2f} | {:.2f} | {} |\n",
                      rad_to_deg(r.theta_i), phi_text(r.phi_i), lobe_names.at(static_cast<std::size_t>(r.lobe)), r.channel,
                      estimate_text(r.sim_energy, r.sim_error, 5), r.model_energy, r.bins.per_dof(), r.bins.dof,
                      r.theta_marginal.per_dof(), r.phi_marginal.per_dof(), r.l1, rad_to_deg(r.centroid_sim),
                      rad_to_deg(r.centroid_model), rad_to_deg(r.measured_shift),
                      !r.judged ? "not judged" : (v.accepted[i] ? "ok" : "rejected"));
  }
  return md;
}

}  // namespace fiberlab::compare
