#pragma once
// A fit's outcome as text (terminal, report.md, metrics.json): the fitted
// values with their uncertainties, and the chi-square before and after the
// fit for every judged lobe (incident direction, lobe, channel).
#include <string>
#include <vector>

#include "compare/fit.h"
#include "compare/verdict.h"

namespace fiberlab::compare {

// `before` and `after`: the verdicts with the start and the fitted parameters
// (same rows, same order).
std::string fit_text(const FitResult& fit, const Verdict& before, const Verdict& after, const std::vector<std::string>& lobe_names);
std::string fit_markdown(const FitResult& fit, const Verdict& before, const Verdict& after, const std::vector<std::string>& lobe_names);
// fit_only_settings: `compare --fit-set`'s KEY=VALUE (compare/fit_settings.h), listed as such.
std::string fit_json(const FitResult& fit, const Verdict& before, const Verdict& after,
                     const std::vector<std::string>& fit_only_settings = {});

}  // namespace fiberlab::compare
