#include "compare/compare_report.h"

#include <fmt/core.h>

#include "compare/report.h"
#include "compare/report_folder.h"
#include "compare/verdict_tables.h"

namespace fiberlab::compare {

namespace {

// Every file of the report, into the folder's staging folder, then moved into place.
std::string write_staged(const CompareReport& rep, ReportFolder& folder, const sim::ResultFile& result,
                         const std::vector<std::vector<double>>& bins, const Verdict& v) {
  const std::string& dir = folder.staging();
  write_text(dir, "metrics.csv", verdict_csv(v, result.lobe_names()));
  const std::string json = fmt::format(
      "{{\n  \"kind\": \"compare\",\n  \"result\": {},\n  \"model\": {},\n  \"params\": {},\n  \"criterion\": {},\n"
      "  \"accepted\": {},\n  \"fit\": {},\n  \"lobes\": {}\n}}\n",
      json_string(rep.result_path), json_string(rep.label), rep.params_json, json_string(v.criterion),
      v.all_accepted ? "true" : "false", rep.fit_json, verdict_json_rows(v, result.lobe_names()));
  write_text(dir, "metrics.json", json);
  write_compare_data(dir, result, bins, rep.label, rep.plot_channel);
  const PlotOutcome plots = make_plots("compare", dir);
  std::string md = fmt::format("# {} against {}\n\n```\n{}```\n\nCriterion per lobe: {}. "
                               "Verdict: **{}** ({} of {} judged lobes accepted).\n\n",
                               rep.result_path, rep.label, rep.header, v.criterion,
                               v.all_accepted ? "accepted" : "rejected", v.judged - v.rejected, v.judged);
  md += verdict_markdown(v, result.lobe_names());
  md += "\n" + rep.fit_markdown;
  md += "\n## Plots\n\n";
  if (plots.html) md += "All figures on one page: [report.html](report.html).\n\n";
  if (!plots.ran) md += plots.message + "\n\n";
  for (const std::string& png : plots.pngs) md += fmt::format("![{}]({})\n\n", png, png);
  md += "Numbers: `metrics.csv`, `metrics.json`; arrays: `report_data.h5`.\n";
  write_text(dir, "report.md", md);
  folder.commit();
  return fmt::format("report: {}/report.md{}{}\n", rep.dir,
                     plots.html ? fmt::format(", {}/report.html", rep.dir) : "",
                     plots.ran ? "" : " (" + plots.message + ")");
}

}  // namespace

std::string write_compare_report(const CompareReport& rep, const sim::ResultFile& result,
                                 const std::vector<std::vector<double>>& bins, const Verdict& v) {
  ReportFolder folder(rep.dir);
  try {
    return write_staged(rep, folder, result, bins, v);
  } catch (const std::exception& e) {
    folder.rethrow(e);
  }
}

}  // namespace fiberlab::compare
