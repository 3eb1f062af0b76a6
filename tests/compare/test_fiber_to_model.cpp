// From a simulated fiber's roughness to each model's parameters
// (analytic/physical_defaults.h, ModelInfo::from_fiber): a microfacet fiber
// reaches huang2022 as a microfacet fiber, a fiber a model cannot represent
// is refused naming the field, and an approximate mapping is stated.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "analytic/chiang2016.h"
#include "analytic/deon2011.h"
#include "analytic/huang2022.h"
#include "analytic/marschner2003.h"
#include "common/error.h"
#include "tests/compare/compare_test_support.h"

namespace fiberlab::compare {
namespace {

sim::Settings microfacet_fiber(sim::MicrofacetModel model, double alpha_long, double alpha_azim) {
  return testing::circle(30.0, 1000, sim::testing::microfacet(model, alpha_long, alpha_azim));
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
    const analytic::ModelParameters p =
        params_for(microfacet_fiber(sim::MicrofacetModel::GGX, alpha, alpha), parse_model_spec("huang2022"), {}, &notes);
    EXPECT_EQ(p.as<analytic::Huang2022Params>().roughness, alpha);
    EXPECT_TRUE(notes.empty()) << notes.front();  // the same distribution: nothing approximated
  }
}

// An anisotropic GGX fiber (alpha [0.3, 0.1]) is never predicted as an
// isotropic one: huang2022 refuses it, naming the field and what it allows;
// with --set roughness the user's choice stands.
TEST(FiberToModel, AnisotropicGgxFiberIsRefusedByHuang) {
  const sim::Settings s = microfacet_fiber(sim::MicrofacetModel::GGX, 0.3, 0.1);
  const std::string why = refusal(s, "huang2022");
  EXPECT_NE(why.find("roughness"), std::string::npos) << why;
  EXPECT_NE(why.find("anisotropic"), std::string::npos) << why;
  EXPECT_NE(why.find("--set roughness"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;  // one line
  EXPECT_EQ(params_for(s, parse_model_spec("huang2022"), {"roughness=0.2"}).as<analytic::Huang2022Params>().roughness, 0.2);
  EXPECT_EQ(params_for(s, parse_model_spec("huang2022:roughness=0.25"), {}).as<analytic::Huang2022Params>().roughness,
            0.25);
  // The same for the other fibers it has no isotropic GGX for.
  EXPECT_NE(refusal(microfacet_fiber(sim::MicrofacetModel::Beckmann, 0.3, 0.1), "huang2022").find("anisotropic"),
            std::string::npos);
  EXPECT_NE(refusal(microfacet_fiber(sim::MicrofacetModel::GGX, 2.0, 2.0), "huang2022").find("outside [0, 1]"),
            std::string::npos);
  sim::Settings blur = testing::circle(30.0, 1000, fiberlab::roughness::ExitBlur{});
  sim::testing::roughness_of<fiberlab::roughness::ExitBlur>(blur).beta_long = {deg_to_rad(5.0)};
  EXPECT_NE(refusal(blur, "huang2022").find("exit_blur"), std::string::npos);
  EXPECT_EQ(params_for(blur, parse_model_spec("huang2022"), {"roughness=0.1"}).as<analytic::Huang2022Params>().roughness,
            0.1);
}

// The Gaussian-width models read a microfacet fiber per axis (beta = atan(alpha
// / sqrt 2), physical_defaults.h) and say so: the azimuthal alpha reaches
// beta_azim (a fiber [0.3, 0.1] differs from [0.3, 0.3] there, not in beta_long).
TEST(FiberToModel, GaussianWidthModelsKeepTheAzimuthalAlphaAndStateTheMapping) {
  for (const std::string model : {"deon2011", "chiang2016", "marschner2003"}) {
    std::vector<std::string> notes;
    const analytic::ModelParameters aniso = params_for(microfacet_fiber(sim::MicrofacetModel::GGX, 0.3, 0.1),
                                                   parse_model_spec(model), {}, &notes);
    const analytic::ModelParameters iso =
        params_for(microfacet_fiber(sim::MicrofacetModel::GGX, 0.3, 0.3), parse_model_spec(model), {});
    // marschner2003 also says that the azimuthal width is not represented.
    ASSERT_EQ(notes.size(), model == "marschner2003" ? 2u : 1u) << model;
    EXPECT_NE(notes.front().find("ggx alpha = [0.3, 0.1]"), std::string::npos) << notes.front();
    if (model == "marschner2003") {
      EXPECT_NE(notes.back().find("no azimuthal roughness"), std::string::npos) << notes.back();
    }
    if (model == "chiang2016") {
      const auto &a = aniso.as<analytic::Chiang2016Params>(), &i = iso.as<analytic::Chiang2016Params>();
      EXPECT_EQ(a.beta_m, i.beta_m);
      EXPECT_LT(a.beta_n, i.beta_n);
    } else if (model == "deon2011") {
      const auto &a = aniso.as<analytic::Deon2011Params>(), &i = iso.as<analytic::Deon2011Params>();
      EXPECT_EQ(a.beta_long, i.beta_long) << model;
      EXPECT_LT(analytic::for_lobe(a.beta_azim, 0), analytic::for_lobe(i.beta_azim, 0)) << model;
      // Per axis: beta_azim of R is the first-order spread 2 times atan(0.1 / sqrt 2).
      EXPECT_DOUBLE_EQ(a.beta_azim.front(), 2.0 * std::atan(0.1 / std::sqrt(2.0)));
    } else {
      // marschner2003 has no azimuthal width (marschner2003.h): the
      // longitudinal widths are the axis's own.
      EXPECT_EQ(aniso.as<analytic::Marschner2003Params>().beta_long,
                iso.as<analytic::Marschner2003Params>().beta_long)
          << model;
    }
  }
}

// marschner2003 has no azimuthal width: a gaussian fiber's beta_azim is not
// represented, and the mapping says so; a smooth fiber has none to drop.
TEST(FiberToModel, MarschnerSaysTheAzimuthalWidthIsNotRepresented) {
  std::vector<std::string> notes;
  params_for(testing::circle(30.0, 1000, fiberlab::roughness::Gaussian{deg_to_rad(5.0), deg_to_rad(5.0)}),
             parse_model_spec("marschner2003"), {}, &notes);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes.front().find("no azimuthal roughness"), std::string::npos) << notes.front();
  notes.clear();
  params_for(testing::circle(30.0, 1000, fiberlab::roughness::Smooth{}), parse_model_spec("marschner2003"), {},
             &notes);
  EXPECT_TRUE(notes.empty()) << notes.front();
}

}  // namespace
}  // namespace fiberlab::compare
