#include "compare/energy_report.h"

#include <fmt/core.h>

#include "common/units.h"
#include "compare/comparison.h"
#include "compare/report.h"
#include "compare/report_folder.h"

namespace fiberlab::compare {

namespace {

std::string curve_json(const EnergyCurve& e, int c, const std::vector<std::string>& lobe_names) {
  auto arr = [](const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += fmt::format("{}{}", s.empty() ? "" : ", ", json_number(x));
    return "[" + s + "]";
  };
  const std::size_t K = e.theta_i.size();
  std::vector<double> th, total, total_err, three, absorbed, truncated, lost, ledger;
  std::string lobes = "[", errors = "[", names = "[";
  for (int l = 0; l < e.lobes; ++l) {
    std::vector<double> v, err;
    for (std::size_t k = 0; k < K; ++k) {
      v.push_back(e.at(k, l, c));
      err.push_back(e.error(k, l, c));
    }
    const char* sep = l ? ", " : "";
    lobes += sep;
    lobes += arr(v);
    errors += sep;
    errors += arr(err);
    names += fmt::format("{}\"{}\"", l ? ", " : "", lobe_names.at(l));
  }
  for (std::size_t k = 0; k < K; ++k) {
    th.push_back(rad_to_deg(e.theta_i[k]));
    total.push_back(e.total(k, c));
    total_err.push_back(e.total_error(k, c));
    three.push_back(e.three_lobe(k, c));
    if (e.simulated) {
      absorbed.push_back(e.absorbed[k * e.channels + c]);
      truncated.push_back(e.truncated[k * e.channels + c]);
      lost.push_back(e.lost[k * e.channels + c]);
      ledger.push_back(e.ledger[k * e.channels + c]);
    }
  }
  return fmt::format(
      "{{\"label\": {}, \"simulated\": {}, \"beta_long_deg\": {}, \"theta_i_deg\": {}, \"lobe_names\": {}], "
      "\"lobes\": {}], \"lobe_errors\": {}], \"total\": {}, \"total_error\": {}, \"three_lobe\": {}, "
      "\"absorbed\": {}, \"truncated\": {}, \"lost\": {}, \"ledger\": {}}}",
      json_string(e.label), e.simulated ? "true" : "false",
      e.beta_long >= 0 ? json_number(rad_to_deg(e.beta_long)) : std::string("null"), arr(th), names, lobes,
      errors, arr(total), arr(total_err), arr(three), arr(absorbed), arr(truncated), arr(lost), arr(ledger));
}

}  // namespace

std::string energy_csv(const EnergyReport& r, const std::vector<EnergyCurve>& curves) {
  const bool white = r.white;
  const std::vector<double>& theta_i = r.theta_i;
  std::string csv = "source,beta_long_deg,theta_i_deg,channel";
  const int L = curves.front().lobes;
  for (int l = 0; l < L; ++l) csv += fmt::format(",{0},{0}_error", r.lobe_names.at(l));
  csv += ",total,total_error,three_lobe,absorbed,truncated,lost,ledger,furnace_departure\n";
  for (std::size_t k = 0; k < theta_i.size(); ++k) {
    for (const auto& e : curves) {
      for (int ch = 0; ch < e.channels; ++ch) {
        csv += fmt::format("\"{}\",{},{:.6g},{}", e.label, e.beta_long >= 0 ? fmt::format("{:g}", rad_to_deg(e.beta_long)) : "",
                           rad_to_deg(theta_i[k]), ch);
        for (int l = 0; l < e.lobes; ++l) csv += fmt::format(",{:.9g},{:.3g}", e.at(k, l, ch), e.error(k, l, ch));
        csv += fmt::format(",{:.9g},{:.3g},{:.9g}", e.total(k, ch), e.total_error(k, ch), e.three_lobe(k, ch));
        if (e.simulated)
          csv += fmt::format(",{:.9g},{:.3g},{:.9g},{:.15g}", e.absorbed[k * e.channels + ch],
                             e.truncated[k * e.channels + ch], e.lost[k * e.channels + ch],
                             e.ledger[k * e.channels + ch]);
        else
          csv += ",,,,";
        csv += white ? fmt::format(",{:.6g}\n", e.total(k, ch) - 1.0) : std::string(",\n");
      }
    }
  }
  return csv;
}

std::string write_energy_report(const EnergyReport& r, const std::vector<EnergyCurve>& curves) {
  const bool white = r.white, simulated = r.simulated;
  const int c = r.channel;
  const std::vector<double>& theta_i = r.theta_i;
  ReportFolder folder(r.dir);
  try {
    const std::string& dir = folder.staging();
    write_text(dir, "metrics.csv", energy_csv(r, curves));
    std::string js;
    for (const auto& e : curves) js += (js.empty() ? "\n    " : ",\n    ") + curve_json(e, c, r.lobe_names);
    write_text(dir, "metrics.json",
               fmt::format("{{\n  \"kind\": \"energy\",\n  \"input\": {},\n  \"simulated\": {},\n"
                           "  \"white\": {},\n  \"channel\": {},\n  \"curves\": [{}\n  ]\n}}\n",
                           json_string(r.input), simulated ? "true" : "false",
                           white ? "true" : "false", c, js));
    const PlotOutcome plots = make_plots("energy", dir);
    std::string md = fmt::format("# Energy: {}\n\n{}. Channel {}. Models integrated over the sphere on a "
                                 "{} x {} grid (sum of bin probabilities).\n\n",
                                 r.input,
                                 simulated ? "Simulated and predicted" : "Models only (the simulation was not run)",
                                 c, r.n_theta, r.n_phi);
    md += "| source | theta_i | total | R+TT+TRT |" + std::string(white ? " total - 1 |" : "") +
          "\n|---|---|---|---|" + (white ? "---|" : "") + "\n";
    for (const auto& e : curves)
      for (std::size_t k = 0; k < theta_i.size(); ++k)
        md += fmt::format("| {} | {:.1f} | {:.5f} | {:.5f} |{}\n", e.label, rad_to_deg(theta_i[k]), e.total(k, c),
                          e.three_lobe(k, c), white ? fmt::format(" {:+.4f} |", e.total(k, c) - 1.0) : "");
    md += "\n## Plots\n\n";
    if (plots.html) md += "All figures on one page: [report.html](report.html).\n\n";
    if (!plots.ran) md += plots.message + "\n\n";
    for (const std::string& png : plots.pngs) md += fmt::format("![{}]({})\n\n", png, png);
    md += "Numbers: `metrics.csv` (every channel), `metrics.json`.\n";
    write_text(dir, "report.md", md);
    folder.commit();
    return fmt::format("\nreport: {}/report.md{}{}\n", r.dir,
                       plots.html ? fmt::format(", {}/report.html", r.dir) : "",
                       plots.ran ? "" : " (" + plots.message + ")");
  } catch (const std::exception& e) {
    folder.rethrow(e);
  }
}

}  // namespace fiberlab::compare
