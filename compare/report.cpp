#include "compare/report.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/h5_file.h"
#include "common/result_layout.h"
#include "compare/report_folder.h"
#include "compare/verdict_tables.h"

#ifndef FIBERLAB_SOURCE_DIR
#define FIBERLAB_SOURCE_DIR ""
#endif

namespace fiberlab::compare {

namespace fs = std::filesystem;

void make_report_dir(const std::string& dir) { check_report_dir_possible(dir); }

void write_text(const std::string& dir, const std::string& name, const std::string& text) {
  AtomicOutput out((fs::path(dir) / name).string());
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    errno = 0;
    f << text;
    f.close();  // a full disk shows here
    if (!f) throw Error(fmt::format("cannot write {}: {}", out.target(), std::strerror(errno)));
  }
  out.commit();
}

void write_compare_data(const std::string& dir, const sim::ResultFile& r,
                        const std::vector<std::vector<double>>& model_bins,
                        const std::string& model_label, int plot_channel) {
  AtomicOutput out((fs::path(dir) / "report_data.h5").string());
  {
    h5::File f = h5::File::create(out.temp_path(), out.target());
    const std::size_t K = r.configs();
    const hsize_t L = r.lobes, nt = r.grid.n_theta(), np = r.grid.n_phi(), C = r.channels;
    write_file_identity(f, "fiber-report-data", utc_timestamp());
    f.set_attr("/", "kind", std::string("compare"));
    f.set_attr("/", "model", model_label);
    f.set_attr("/", "plot_channel", static_cast<std::int64_t>(plot_channel));
    f.set_attr("/", "config_yaml", r.config_yaml);
    write_axis_names(f, r.lobe_names(), r.channels, r.settings.fiber.eumelanin.has_value());
    f.write("theta_edges", {nt + 1}, r.grid.theta_edges);
    f.write("phi_edges", {np + 1}, r.grid.phi_edges);
    std::vector<double> omega(nt * np);
    for (hsize_t i = 0; i < nt; ++i)
      for (hsize_t j = 0; j < np; ++j) omega[i * np + j] = r.grid.solid_angle(i, j);
    f.write("solid_angle", {nt, np}, omega);
    f.write("theta_i", {K}, r.theta_i);
    f.write("phi_i", {K}, r.phi_i);  // NaN: a randomly rotated fiber
    f.write("photons", {K}, r.photons);
    std::vector<double> p(r.weight_sum.size()), se(r.weight_sum.size()), m;
    m.reserve(r.weight_sum.size());
    for (std::size_t k = 0; k < K; ++k) {
      const std::size_t base = k * r.bin_cells();
      for (std::size_t b = 0; b < r.bin_cells(); ++b) {
        const sim::Estimate e = sim::bin_estimate(r.weight_sum[base + b], r.weight_sq_sum[base + b], r.photons[k]);
        p[base + b] = e.mean;
        se[base + b] = e.std_error;
      }
      m.insert(m.end(), model_bins[k].begin(), model_bins[k].end());
    }
    const h5::Dims dims{K, L, nt, np, C};
    f.write("sim_p", dims, p);
    f.write("sim_se", dims, se);
    f.write("model_p", dims, m);
    describe_bins_and_source(f, {.bins = "/", .source = "/"});
    describe(f, "/photons", "incidence", "photons", "photons launched per incident direction");
    describe(f, "/sim_p", kHistogramDims, "probability", "simulated probability of each bin, S1/N");
    describe(f, "/sim_se", kHistogramDims, "probability", "standard error of sim_p");
    describe(f, "/model_p", kHistogramDims, "probability", "the model's probability of each bin");
    f.close();
  }
  out.commit();
}

std::string describe_report_data(const std::string& path) {
  const h5::File f = h5::File::open_read(path);
  const h5::Dims d = f.shape("/sim_p");
  if (d.size() != 5 || d[0] == 0)
    throw Error(fmt::format("{}: /sim_p must be K x L x n_theta x n_phi x C with K >= 1", path));
  const std::vector<double> theta_i = f.read_doubles("/theta_i", {d[0]}, "sim_p's first dimension");
  const std::vector<double> phi_i = f.read_doubles("/phi_i", {d[0]}, "sim_p's first dimension");
  const std::vector<double> sim = f.read_doubles("/sim_p", d, "");
  const std::vector<double> model = f.read_doubles("/model_p", d, "sim_p's shape");
  const std::size_t L = d[1], bins = d[2] * d[3], C = d[4];
  // The lobes as the file names them (a medullated fiber's last is `scattered`).
  const std::vector<std::string> lobe_names = split_names(f.attr_string("/", "lobe_names"));
  if (lobe_names.size() != L)
    throw Error(fmt::format("{}: attribute lobe_names names {} lobes; /sim_p has {}", path, lobe_names.size(), L));
  std::string s = fmt::format("{}: fiberlab report data of `{}` (model {}; software {}, created {})\n", path,
                              f.attr_string("/", "kind"), f.attr_string("/", "model"),
                              f.attr_string("/", "software_version"), f.attr_string("/", "created_utc"));
  s += fmt::format("bins: {} x {} (theta x phi), lobes {}, channels {}, {} incident direction(s)\n", d[2], d[3],
                   f.attr_string("/", "lobe_names"), f.attr_string("/", "channel_names"), d[0]);
  s += "lobe energies, simulated / model, per channel:\n";
  for (std::size_t k = 0; k < d[0]; ++k) {
    s += incidence_label(theta_i[k], phi_i[k]) + ":";
    for (std::size_t l = 0; l < L; ++l) {
      s += fmt::format("  {}", lobe_names[l]);
      for (std::size_t c = 0; c < C; ++c) {
        double e_sim = 0.0, e_model = 0.0;
        for (std::size_t b = 0; b < bins; ++b) {
          e_sim += sim[((k * L + l) * bins + b) * C + c];
          e_model += model[((k * L + l) * bins + b) * C + c];
        }
        s += fmt::format(" {:.4f}/{:.4f}", e_sim, e_model);
      }
    }
    s += "\n";
  }
  return s;
}

std::string plot_script_path() {
  if (const char* env = std::getenv("FIBERLAB_PLOT_SCRIPT"); env && *env)
    return fs::exists(env) ? std::string(env) : std::string();
  const fs::path p = fs::path(FIBERLAB_SOURCE_DIR) / "scripts" / "plot_report.py";
  return std::string(FIBERLAB_SOURCE_DIR).empty() || !fs::exists(p) ? std::string() : p.string();
}

namespace {

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

PlotOutcome make_plots(const std::string& kind, const std::string& dir) {
  PlotOutcome o;
  std::string python = "/usr/bin/python3";
  if (const char* env = std::getenv("FIBERLAB_PYTHON"); env && *env) python = env;
  const std::string script = plot_script_path();
  if (script.empty()) {
    o.message = "plots skipped: scripts/plot_report.py not found (set FIBERLAB_PLOT_SCRIPT)";
    return o;
  }
  if (!fs::exists(python)) {
    o.message = fmt::format("plots skipped: {} not found", python);
    return o;
  }
  const fs::path page = fs::path(dir) / "report.html";
  const std::string log = (fs::path(dir) / "plot_log.txt").string();
  const std::string cmd = fmt::format("{} {} {} {} > {} 2>&1", shell_quote(python), shell_quote(script),
                                      kind, shell_quote(dir), shell_quote(log));
  const int status = std::system(cmd.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::string tail;
  {
    std::ifstream f(log);
    std::string line;
    while (std::getline(f, line)) tail = line;
  }
  if (code == 0) {
    o.ran = true;
    fs::remove(log);
  } else if (code == 3) {
    o.message = fmt::format("plots skipped: {} ({})", tail, python);
  } else {
    o.message = fmt::format("plots failed (exit status {}; see plot_log.txt in the report folder): {}", code, tail);
  }
  if (code != 0) fs::remove(page);  // the page of a failed script is not the report's
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".png") o.pngs.push_back(entry.path().filename().string());
  std::sort(o.pngs.begin(), o.pngs.end());
  o.html = o.ran && fs::exists(page);
  return o;
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", static_cast<int>(c));
        else out += c;
    }
  }
  return out + "\"";
}

std::string json_number(double v) { return std::isfinite(v) ? fmt::format("{:.10g}", v) : "null"; }

}  // namespace fiberlab::compare
