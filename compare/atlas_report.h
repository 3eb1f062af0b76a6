#pragma once
// The atlas's report folder (`fiberlab atlas --report DIR`): report.md (the
// tables), atlas_tables.md (the same tables for the page), report_data.h5 (a copy of
// the atlas file, for the plots), and, through scripts/plot_report.py
// (kind "atlas", scripts/plot_atlas.py), the summary figures and
// report.html. Numbers come from compare/atlas.h; nothing is computed here
// but medians and maxima of them.
#include <string>
#include <vector>

#include "compare/atlas.h"

namespace fiberlab::compare {

// The headline: per model and lobe, over the fibers the model applies to,
// the median of each fiber's largest |E_model - E_sim| and of chi2/dof,
// before and after the fit (with fit.per_lobe: after the joint fit and
// after each lobe's own fit) (Markdown).
std::string atlas_headline_markdown(const AtlasConfig& config, const std::vector<AtlasFiberResult>& fibers);
// Per fiber and model: status, fitted parameters +- errors, per lobe
// |dE| and chi2/dof before -> after (with fit.per_lobe: each lobe's fitted
// values, and before -> after joint fit -> after per-lobe fit) (Markdown).
std::string atlas_table_markdown(const AtlasConfig& config, const std::vector<AtlasFiberResult>& fibers);

// Writes the folder (`atlas_path`: the atlas file already written, copied
// as report_data.h5); returns the line to print.
std::string write_atlas_report(const std::string& dir, const std::string& atlas_path, const AtlasConfig& config,
                               const std::vector<AtlasFiberResult>& fibers, const std::string& command);

}  // namespace fiberlab::compare
