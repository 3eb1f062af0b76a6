#include "common/roughness/microfacet.h"

#include <fmt/format.h>

namespace fiberlab::roughness {
namespace {

const config::Rule kAlpha{"must be in (0, 10]", [](double x) { return x > 0.0 && x <= 10.0; }};

// alpha: a number (isotropic) or [longitudinal, azimuthal].
void read_alpha(const config::Reader& r, const YAML::Node& n, MicrofacetAlpha& g) {
  const std::string path = "roughness.alpha";
  const config::Rule rule{kAlpha.text + "; a number, or a list [longitudinal, azimuthal]", kAlpha.ok};
  const std::vector<double> alpha = r.numbers(n, path, rule, true);
  if (alpha.size() > 2)
    r.bad(path, n, fmt::format("has {} entries", alpha.size()),
          "must be a number or a list of two: [longitudinal, azimuthal], each in (0, 10]");
  g.alpha_long = alpha.front();
  g.alpha_azim = alpha.back();
}

}  // namespace

const std::vector<std::string>& MicrofacetAlpha::keys() {
  static const std::vector<std::string> keys{"alpha", "masking"};
  return keys;
}

MicrofacetAlpha MicrofacetAlpha::read(const config::Reader& r, const YAML::Node& n, const std::string& model) {
  // The beta keys belong to the other models.
  for (const char* key : {"beta_long", "beta_azim"})
    if (n[key])
      r.bad(std::string("roughness.") + key, n[key], "is not allowed for model " + model,
            "models beckmann and ggx take alpha; beta_long and beta_azim belong to smooth, "
            "gaussian and exit_blur");
  if (!n["alpha"])
    r.fail(fmt::format("roughness.alpha is missing (model {} needs alpha in (0, 10]: a number, "
                       "or a list [longitudinal, azimuthal])", model));
  MicrofacetAlpha g;
  read_alpha(r, n["alpha"], g);
  if (n["masking"]) g.masking = static_cast<Masking>(r.word(n["masking"], "roughness.masking", kMaskingNames));
  return g;
}

std::string MicrofacetAlpha::yaml() const {
  const std::string alpha = alpha_long == alpha_azim
                                ? config::number_text(alpha_long)
                                : config::list_text({alpha_long, alpha_azim}, config::number_text);
  return fmt::format("  alpha: {}\n  masking: {}\n", alpha, to_string(masking));
}

std::vector<Attribute> MicrofacetAlpha::attributes() const {
  // beta_long and beta_azim are on every model's /roughness (docs/FILE_FORMAT.md): 0 here.
  return {{"beta_long", std::vector<double>{0.0}},
          {"beta_azim", std::vector<double>{0.0}},
          {"alpha", std::vector<double>{alpha_long, alpha_azim}},
          {"masking", to_string(masking)}};
}

std::string MicrofacetAlpha::describe() const {
  return fmt::format("alpha_long {}, alpha_azim {}, masking {}", alpha_long, alpha_azim, to_string(masking));
}

std::string MicrofacetAlpha::text(const std::string& model) const {
  return fmt::format("{} alpha = [{:g}, {:g}]", model, alpha_long, alpha_azim);
}

}  // namespace fiberlab::roughness
