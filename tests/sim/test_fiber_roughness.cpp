// The fiber's roughness as one type per model (common/roughness/roughness.h):
// each model's config reading, its file attributes (docs/FILE_FORMAT.md,
// /roughness), its `fiberlab info` line and its YAML text, and the tracers'
// choice of sampler by type (sim/roughness/roughness_models.h).
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "common/units.h"
#include "sim/roughness/roughness_models.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {
namespace {

Roughness parse_roughness(const std::string& block) {
  return parse_settings_yaml("roughness: " + block + "\n", "test.yaml").fiber.roughness;
}

// The attributes as docs/FILE_FORMAT.md lists them: name -> numbers or text.
std::vector<std::pair<std::string, std::string>> attribute_text(const Roughness& g) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const roughness::Attribute& a : roughness::attributes(g)) {
    std::string value;
    if (const auto* x = std::get_if<std::vector<double>>(&a.value))
      for (double v : *x) value += (value.empty() ? "" : ",") + std::to_string(v);
    else
      value = std::get<std::string>(a.value);
    out.emplace_back(a.name, value);
  }
  return out;
}

using Attributes = std::vector<std::pair<std::string, std::string>>;

// docs/FILE_FORMAT.md /roughness: beta_long and beta_azim (radians) on every
// model; alpha [longitudinal, azimuthal] and masking on beckmann and ggx.
TEST(FiberRoughness, FileAttributesAreEachModelsOwnFields) {
  const Roughness ggx = parse_roughness("{model: ggx, alpha: [0.3, 0.1], masking: smith_g1}");
  EXPECT_EQ(roughness::name(ggx), "ggx");
  EXPECT_EQ(attribute_text(ggx), (Attributes{{"beta_long", "0.000000"},
                                             {"beta_azim", "0.000000"},
                                             {"alpha", "0.300000,0.100000"},
                                             {"masking", "smith_g1"}}));
  const Roughness beckmann = parse_roughness("{model: beckmann, alpha: 0.2}");
  EXPECT_EQ(attribute_text(beckmann), (Attributes{{"beta_long", "0.000000"},
                                                  {"beta_azim", "0.000000"},
                                                  {"alpha", "0.200000,0.200000"},
                                                  {"masking", "none"}}));
  const Roughness gaussian = parse_roughness("{model: gaussian, beta_long: 45, beta_azim: 90}");
  EXPECT_EQ(attribute_text(gaussian),
            (Attributes{{"beta_long", std::to_string(kPi / 4)}, {"beta_azim", std::to_string(kPi / 2)}}));
  const Roughness blur = parse_roughness("{model: exit_blur, beta_long: [45, 90]}");
  const std::string both = std::to_string(kPi / 4) + "," + std::to_string(kPi / 2);
  EXPECT_EQ(attribute_text(blur), (Attributes{{"beta_long", both}, {"beta_azim", both}}));
}

// The `fiberlab info` line of each model (app/info.cpp prints it after "roughness: ").
TEST(FiberRoughness, DescribeNamesTheModelAndItsFields) {
  EXPECT_EQ(roughness::describe(parse_roughness("{model: ggx, alpha: [0.3, 0.1], masking: smith_g1}")),
            "ggx, alpha_long 0.3, alpha_azim 0.1, masking smith_g1");
  EXPECT_EQ(roughness::describe(parse_roughness("{model: exit_blur, beta_long: [5, 10], beta_azim: 2}")),
            "exit_blur, beta_long [5, 10] deg, beta_azim [2] deg");
  EXPECT_EQ(roughness::text(parse_roughness("{model: beckmann, alpha: [0.3, 0.1]}")),
            "beckmann alpha = [0.3, 0.1]");
  EXPECT_EQ(roughness::text(parse_roughness("{model: gaussian, beta_long: 5, beta_azim: 7}")),
            "gaussian beta = [5, 7] deg");
}

// An absent roughness section is gaussian with both widths 0 (SPEC section
// 11's default), which the tracers run as the smooth model (SPEC section 3).
TEST(FiberRoughness, DefaultIsGaussianZeroRunAsSmooth) {
  const Settings s = parse_settings_yaml("photons: 10\n", "test.yaml");
  ASSERT_TRUE(std::holds_alternative<roughness::Gaussian>(s.fiber.roughness));
  EXPECT_EQ(std::get<roughness::Gaussian>(s.fiber.roughness), (roughness::Gaussian{0.0, 0.0}));
  EXPECT_TRUE(std::holds_alternative<life::SmoothRoughness>(make_roughness(s)));
  Settings rough = s;
  rough.fiber.roughness = roughness::Gaussian{0.0, 0.1};
  EXPECT_TRUE(std::holds_alternative<life::GaussianRoughness>(make_roughness(rough)));
}

// Each model's sampler is picked by the roughness's type.
TEST(FiberRoughness, EachModelGetsItsSampler) {
  Settings s;
  s.fiber.roughness = parse_roughness("{model: smooth, beta_long: 5}");
  EXPECT_TRUE(std::holds_alternative<life::SmoothRoughness>(make_roughness(s)));
  s.fiber.roughness = parse_roughness("{model: exit_blur, beta_long: 5}");
  EXPECT_TRUE(std::holds_alternative<ExitBlurRoughness>(make_roughness(s)));
  s.fiber.roughness = parse_roughness("{model: ggx, alpha: 0.3}");
  EXPECT_TRUE(std::holds_alternative<MicrofacetLifeModel>(make_roughness(s)));
  s.fiber.roughness = parse_roughness("{model: beckmann, alpha: 0.3, masking: smith_g1}");
  ASSERT_TRUE(std::holds_alternative<MicrofacetLifeModel>(make_roughness(s)));
  EXPECT_TRUE(std::get<MicrofacetLifeModel>(make_roughness(s)).roughness.masks());
}

// The fiber block of to_yaml reads back to the same fiber, roughness included.
TEST(FiberRoughness, FiberYamlReadsBackEqual) {
  for (const char* yaml :
       {"fiber: {melanin: {eumelanin: 0.3, pheomelanin: 0.05}, scale_tilt: 2.5}\n"
        "roughness: {model: exit_blur, beta_long: [3, 7.5], beta_azim: 11}\n",
        "fiber: {sigma_a: [0.1, 0.2], medulla: {radius: 0.4, sigma_s: 2, g: 0.1}}\n"
        "roughness: {model: beckmann, alpha: [0.25, 0.5]}\n",
        "fiber: {eccentricity: 0.7}\nroughness: {model: smooth, beta_long: [1, 2]}\n"}) {
    const Settings s = parse_settings_yaml(yaml, "test.yaml");
    const std::string text = fiber_yaml(s.fiber);
    const Settings back = parse_settings_yaml(text, "back.yaml");
    EXPECT_EQ(back.fiber, s.fiber) << text;
  }
}

}  // namespace
}  // namespace fiberlab::sim
