#pragma once
// Report folders (`--report DIR`): metrics.csv and metrics.json (written by
// the commands), report_data.h5 (the arrays the plots need), PNG plots and
// report.html (one self-contained page, figures embedded) made by
// scripts/plot_report.py with Debian's /usr/bin/python3 (matplotlib, h5py,
// numpy), and report.md linking them. Without that Python the numbers
// are still written and the report says the plots were skipped.
#include <string>
#include <vector>

#include "sim/store/result_file.h"

namespace fiberlab::compare {

// Checks that DIR can be made (compare/report_folder.h), before any work;
// throws fiberlab::Error when it cannot. The report's files are written into
// a ReportFolder's staging folder: `dir` below is that folder.
void make_report_dir(const std::string& dir);

// Writes `text` to DIR/name atomically.
void write_text(const std::string& dir, const std::string& name, const std::string& text);

// report_data.h5 for `compare`: bin edges, solid angles, theta_i, and per k
// the simulated P = S1/N, its standard error and the model's bin
// probabilities, each K x L x n_theta x n_phi x C (SPEC s9 index order).
void write_compare_data(const std::string& dir, const sim::ResultFile& result,
                        const std::vector<std::vector<double>>& model_bins,
                        const std::string& model_label, int plot_channel);

// What `fiberlab info` prints for a compare report's report_data.h5: the
// model, the bins, lobes and channels, and per incident direction each
// lobe's simulated and predicted energy (the sums of sim_p and model_p).
std::string describe_report_data(const std::string& path);

// The plotting script: $FIBERLAB_PLOT_SCRIPT, else
// FIBERLAB_SOURCE_DIR/scripts/plot_report.py. Empty when neither exists.
std::string plot_script_path();

struct PlotOutcome {
  bool ran = false;
  std::string message;            // why plots were skipped, or the script's complaint
  std::vector<std::string> pngs;  // file names in DIR, sorted
  bool html = false;              // DIR/report.html written
};
// Runs `/usr/bin/python3 SCRIPT KIND DIR` (KIND "compare", "energy" or
// "atlas") with its output in DIR/plot_log.txt (DIR: a fresh staging folder).
// $FIBERLAB_PYTHON replaces /usr/bin/python3 (tests use it to simulate a
// machine without matplotlib).
PlotOutcome make_plots(const std::string& kind, const std::string& dir);

// JSON string literal.
std::string json_string(const std::string& s);
// A finite number as JSON (NaN / inf as null).
std::string json_number(double v);

}  // namespace fiberlab::compare
