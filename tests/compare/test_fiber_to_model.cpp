// From a simulated fiber's roughness to each model's parameters
// (analytic/physical_defaults.h, ModelInfo::from_fiber): a microfacet fiber
// reaches huang2022 as a microfacet fiber, a fiber a model cannot represent
// is refused naming the field, and an approximate mapping is stated.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/error.h"
#include "tests/compare/compare_test_support.h"

namespace fiberlab::compare {
namespace {

sim::Settings microfacet_fiber(sim::RoughnessModel model, double alpha_long, double alpha_azim) {
  sim::Settings s = testing::circle(30.0, 1000, model);
  s.roughness.alpha_long = alpha_long;
  s.roughness.alpha_azim = alpha_azim;
  return s;
}

std::string refusal(const sim::Settings& s, const std::string& model) {
  try {
    params_for(s, parse_model_spec(model), {});
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// huang2022's facets are isotropic GGX: a GGX fiber's alpha is its roughness,
// the number itself (no round trip through a gaussian width).
TEST(FiberToModel, IsotropicGgxFiberIsHuangsRoughnessItself) {
  for (double alpha : {0.1, 0.3, 0.7}) {
    std::vector<std::string> notes;
    const analytic::ModelParams p =
        params_for(microfacet_fiber(sim::RoughnessModel::GGX, alpha, alpha), parse_model_spec("huang2022"), {}, &notes);
    EXPECT_EQ(p.ggx_roughness, alpha);
    EXPECT_TRUE(notes.empty()) << notes.front();  // the same distribution: nothing approximated
  }
}

// An anisotropic GGX fiber (alpha [0.3, 0.1]) is never predicted as an
// isotropic one: huang2022 refuses it, naming the field and what it allows;
// with --set roughness the user's choice stands.
TEST(FiberToModel, AnisotropicGgxFiberIsRefusedByHuang) {
  const sim::Settings s = microfacet_fiber(sim::RoughnessModel::GGX, 0.3, 0.1);
  const std::string why = refusal(s, "huang2022");
  EXPECT_NE(why.find("roughness"), std::string::npos) << why;
  EXPECT_NE(why.find("anisotropic"), std::string::npos) << why;
  EXPECT_NE(why.find("--set roughness"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;  // one line
  EXPECT_EQ(params_for(s, parse_model_spec("huang2022"), {"roughness=0.2"}).ggx_roughness, 0.2);
  EXPECT_EQ(params_for(s, parse_model_spec("huang2022:roughness=0.25"), {}).ggx_roughness, 0.25);
  // The same for the other fibers it has no isotropic GGX for.
  EXPECT_NE(refusal(microfacet_fiber(sim::RoughnessModel::Beckmann, 0.3, 0.1), "huang2022").find("anisotropic"),
            std::string::npos);
  EXPECT_NE(refusal(microfacet_fiber(sim::RoughnessModel::GGX, 2.0, 2.0), "huang2022").find("outside [0, 1]"),
            std::string::npos);
  sim::Settings blur = testing::circle(30.0, 1000, sim::RoughnessModel::ExitBlur);
  blur.roughness.beta_long = {deg_to_rad(5.0)};
  EXPECT_NE(refusal(blur, "huang2022").find("exit_blur"), std::string::npos);
  EXPECT_EQ(params_for(blur, parse_model_spec("huang2022"), {"roughness=0.1"}).ggx_roughness, 0.1);
}

// The Gaussian-width models read a microfacet fiber per axis (beta = atan(alpha
// / sqrt 2), physical_defaults.h) and say so: the azimuthal alpha reaches
// beta_azim (a fiber [0.3, 0.1] differs from [0.3, 0.3] there, not in beta_long).
TEST(FiberToModel, GaussianWidthModelsKeepTheAzimuthalAlphaAndStateTheMapping) {
  for (const std::string model : {"deon2011", "chiang2016", "marschner2003"}) {
    std::vector<std::string> notes;
    const analytic::ModelParams aniso = params_for(microfacet_fiber(sim::RoughnessModel::GGX, 0.3, 0.1),
                                                   parse_model_spec(model), {}, &notes);
    const analytic::ModelParams iso =
        params_for(microfacet_fiber(sim::RoughnessModel::GGX, 0.3, 0.3), parse_model_spec(model), {});
    ASSERT_EQ(notes.size(), 1u) << model;
    EXPECT_NE(notes.front().find("ggx alpha = [0.3, 0.1]"), std::string::npos) << notes.front();
    if (model == "chiang2016") {
      EXPECT_EQ(aniso.beta_m, iso.beta_m);
      EXPECT_LT(aniso.beta_n, iso.beta_n);
    } else {
      EXPECT_EQ(aniso.beta_long, iso.beta_long) << model;
      EXPECT_LT(analytic::for_lobe(aniso.beta_azim, 0), analytic::for_lobe(iso.beta_azim, 0)) << model;
    }
    // Per axis: beta_azim of R is the first-order spread 2 times atan(0.1 / sqrt 2).
    if (model == "deon2011") {
      EXPECT_DOUBLE_EQ(aniso.beta_azim.front(), 2.0 * std::atan(0.1 / std::sqrt(2.0)));
    }
  }
}

}  // namespace
}  // namespace fiberlab::compare
