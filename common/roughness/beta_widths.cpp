#include "common/roughness/beta_widths.h"

#include <fmt/format.h>

#include "common/roughness/masking.h"
#include "common/units.h"

namespace fiberlab::roughness {
namespace {

constexpr std::size_t kMaxBetaEntries = 1024;  // roughness.beta_long/beta_azim lists (8 KiB each)

const config::Rule kBeta{"must be in [0, 90] degrees", [](double x) { return x >= 0.0 && x <= 90.0; }};

// A beta list as YAML: a number when there is one entry.
std::string betas_text(const std::vector<double>& betas) {
  return betas.size() == 1 ? config::degrees_text(betas.front())
                           : config::list_text(betas, config::degrees_text);
}

std::string degrees(const std::vector<double>& radians) {
  std::string s;
  for (double r : radians) s += fmt::format("{}{:g}", s.empty() ? "" : ", ", rad_to_deg(r));
  return "[" + s + "]";
}

}  // namespace

BetaLists read_betas(const config::Reader& r, const YAML::Node& n, const std::string& model, bool lists) {
  if (n["alpha"])
    r.bad("roughness.alpha", n["alpha"], "is not allowed for model " + model,
          "alpha is the roughness of models beckmann and ggx");
  // Masking removes weight at microfacets; these models lose nothing, and
  // `masking: none` says so.
  if (n["masking"] && r.word(n["masking"], "roughness.masking", kMaskingNames) !=
                              static_cast<std::size_t>(Masking::None))
    r.bad("roughness.masking", n["masking"], "is not allowed for model " + model,
          "masking applies to models beckmann and ggx; the other models lose nothing");
  const config::Rule beta{kBeta.text + (lists ? ", a number or a list indexed by p"
                                              : "; a list is allowed only for model exit_blur"),
                          kBeta.ok};
  BetaLists b;
  if (n["beta_long"])
    b.beta_long = config::to_radians(r.numbers(n["beta_long"], "roughness.beta_long", beta, lists));
  b.beta_azim = n["beta_azim"]
                    ? config::to_radians(r.numbers(n["beta_azim"], "roughness.beta_azim", beta, lists))
                    : b.beta_long;
  // Each list is stored in the result as an attribute of /roughness, and an
  // HDF5 1.10 attribute holds at most 64 KiB: refused here, not after the run.
  for (const char* key : {"beta_long", "beta_azim"}) {
    const std::vector<double>& list = std::string(key) == "beta_long" ? b.beta_long : b.beta_azim;
    if (list.size() > kMaxBetaEntries)
      r.bad(std::string("roughness.") + key, n[key], fmt::format("has {} entries", list.size()),
            fmt::format("must have at most {} (one per order p, the last for every larger p)",
                        kMaxBetaEntries));
  }
  return b;
}

std::string betas_yaml(const BetaLists& b) {
  return fmt::format("  beta_long: {}\n  beta_azim: {}\n", betas_text(b.beta_long), betas_text(b.beta_azim));
}

std::vector<Attribute> betas_attributes(const BetaLists& b) {
  return {{"beta_long", b.beta_long}, {"beta_azim", b.beta_azim}};
}

std::string describe_betas(const BetaLists& b) {
  return fmt::format("beta_long {} deg, beta_azim {} deg", degrees(b.beta_long), degrees(b.beta_azim));
}

}  // namespace fiberlab::roughness
