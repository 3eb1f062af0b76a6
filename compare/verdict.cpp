#include "compare/verdict.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace fiberlab::compare {

double acceptance_threshold(double max_chi2, int dof) {
  return max_chi2 > 0.0 ? max_chi2 : 1.0 + 5.0 * std::sqrt(2.0 / std::max(dof, 1));
}

std::string criterion_text(double max_chi2) {
  return max_chi2 > 0 ? fmt::format("chi2/dof <= {:g}", max_chi2)
                      : std::string("chi2/dof <= 1 + 5 sqrt(2/dof)");
}

Verdict judge(std::vector<LobeComparison> rows, double max_chi2) {
  Verdict v;
  v.rows = std::move(rows);
  v.criterion = criterion_text(max_chi2);
  for (const LobeComparison& r : v.rows) {
    const double t = acceptance_threshold(max_chi2, r.bins.dof);
    const bool ok = !r.judged || r.bins.per_dof() <= t;
    v.threshold.push_back(t);
    v.accepted.push_back(ok);
    v.judged += r.judged ? 1 : 0;
    v.rejected += r.judged && !ok ? 1 : 0;
    v.all_accepted = v.all_accepted && ok;
  }
  v.all_accepted = v.all_accepted && v.judged > 0;
  return v;
}

}  // namespace fiberlab::compare
