#pragma once
// The report folder of `fiberlab compare --report DIR`: metrics.csv,
// metrics.json, report_data.h5, the plots and report.md (report.h writes the
// files; this assembles what goes in them).
#include <string>
#include <vector>

#include "compare/verdict.h"
#include "sim/store/result_file.h"

namespace fiberlab::compare {

struct CompareReport {
  std::string dir, result_path;
  std::string label;        // the model spec or the prediction file
  std::string header;       // parameters and approximations in effect
  std::string params_json = "null";
  std::string fit_json = "null", fit_markdown;
  int plot_channel = 0;
};

// Writes every file; returns the line to print ("report: DIR/report.md ...").
std::string write_compare_report(const CompareReport& report, const sim::ResultFile& result,
                                 const std::vector<std::vector<double>>& bins, const Verdict& verdict);

}  // namespace fiberlab::compare
