#pragma once
// The verdict of `fiberlab compare`: is each lobe's chi-square compatible
// with a correct model? A lobe is accepted when chi2/dof <= 1 + 5 sqrt(2/dof)
// (five standard deviations of chi2/dof above its mean 1 for a correct
// model, SPEC s10), or <= a fixed limit (--max-chi2). Lobes with too little
// energy (LobeComparison::judged false) are not judged. Exit status of the
// command: 0 when every judged lobe is accepted and at least one lobe was
// judged, 1 otherwise: a comparison that judged nothing accepts nothing (a
// gate that passes without looking is no gate).
#include <string>
#include <vector>

#include "compare/comparison.h"

namespace fiberlab::compare {

// max_chi2 <= 0: the five-sigma rule.
double acceptance_threshold(double max_chi2, int dof);
std::string criterion_text(double max_chi2);

struct Verdict {
  std::vector<LobeComparison> rows;
  std::vector<bool> accepted;  // per row (true for rows not judged)
  std::vector<double> threshold;
  int judged = 0, rejected = 0;
  bool all_accepted = true;  // every judged lobe accepted, and judged > 0
  std::string criterion;
};

Verdict judge(std::vector<LobeComparison> rows, double max_chi2);

}  // namespace fiberlab::compare
