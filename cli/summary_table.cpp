#include "cli/summary_table.h"

#include <fmt/core.h>

#include <cmath>

#include "common/estimate_text.h"
#include "common/units.h"

namespace fiberlab::cli {

void print_summary(std::FILE* out, const sim::ResultFile& r) {
  const std::vector<std::string> lobe_names = r.lobe_names();
  for (std::size_t k = 0; k < r.configs(); ++k) {
    const double N = static_cast<double>(r.photons[k]);
    const std::string phi = std::isnan(r.phi_i[k]) ? std::string("uniform")
                                                   : fmt::format("{:.2f}", rad_to_deg(r.phi_i[k]));
    fmt::print(out, "theta_i = {:.2f} deg, phi_i = {}, {} photons\n", rad_to_deg(r.theta_i[k]),
               phi, r.photons[k]);
    fmt::print(out, "  {:<10}", "lobe");
    for (int c = 0; c < r.channels; ++c) fmt::print(out, " {:>24}", fmt::format("channel {}", c));
    fmt::print(out, "\n");
    for (int l = 0; l < r.lobes; ++l) {
      fmt::print(out, "  {:<10}", lobe_names.at(static_cast<std::size_t>(l)));
      for (int c = 0; c < r.channels; ++c) {
        const sim::Estimate e = sim::lobe_energy(r, k, l, c);
        fmt::print(out, " {:>24}", estimate_text(e.mean, e.std_error));
      }
      fmt::print(out, "\n");
    }
    fmt::print(out, "  {:<10}", "absorbed");
    for (int c = 0; c < r.channels; ++c)
      fmt::print(out, " {:>24}", fmt::format("{:.6f}", r.absorbed[k * r.channels + c] / N));
    fmt::print(out, "\n  {:<10}", "truncated");
    for (int c = 0; c < r.channels; ++c)
      fmt::print(out, " {:>24}", fmt::format("{:.3e}", r.truncated[k * r.channels + c] / N));
    if (roughness::masking(r.settings.fiber.roughness) != Masking::None) {  // the weight masking removed
      fmt::print(out, "\n  {:<10}", "lost");
      for (int c = 0; c < r.channels; ++c)
        fmt::print(out, " {:>24}", fmt::format("{:.6f}", r.lost[k * r.channels + c] / N));
    }
    if (r.settings.estimator == sim::Estimator::ExpectedValue) {  // signed, expectation 0
      fmt::print(out, "\n  {:<10}", "roulette");
      for (int c = 0; c < r.channels; ++c)
        fmt::print(out, " {:>24}", fmt::format("{:+.3e}", r.roulette[k * r.channels + c] / N));
    }
    fmt::print(out, "\n");
  }
}

}  // namespace fiberlab::cli
