#pragma once
// The verdict of `fiberlab compare` as text: the terminal table, metrics.csv,
// the rows of metrics.json and the Markdown table of report.md. Every row
// names its incident direction by theta_i and phi_i (degrees; "uniform" for
// a randomly rotated fiber, NaN in the files).
#include <string>
#include <vector>

#include "compare/verdict.h"

namespace fiberlab::compare {

// "theta_i 30.00 deg, phi_i 0.00 deg" (or "phi_i uniform").
std::string incidence_label(double theta_i, double phi_i);
// "30.00" / "uniform": phi_i in degrees for tables.
std::string phi_text(double phi_i);

std::string verdict_table(const Verdict& v, const std::vector<std::string>& lobe_names);
std::string verdict_csv(const Verdict& v, const std::vector<std::string>& lobe_names);
std::string verdict_json_rows(const Verdict& v, const std::vector<std::string>& lobe_names);
std::string verdict_markdown(const Verdict& v, const std::vector<std::string>& lobe_names);

}  // namespace fiberlab::compare
