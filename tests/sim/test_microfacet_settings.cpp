// The microfacet roughness block: `roughness: {model: beckmann |
// ggx, alpha: A | [longitudinal, azimuthal], masking: none | smith_g1}`, its
// round trip through to_yaml and its one-line errors.
//
// Mutations run: [longitudinal, azimuthal] read in the other order
// (IsotropicAnisotropicAndMasking: alpha_long 0.4 vs 0.1; the round trip
// fails too); masking read but not stored (masking none vs smith_g1);
// to_yaml writing the list in the other order (RoundTripThroughToYaml).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/error.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {
namespace {

Settings parse(const std::string& yaml) { return parse_settings_yaml(yaml, "configs/x.yaml"); }

std::string error_of(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& yaml, const std::vector<std::string>& pieces) {
  SCOPED_TRACE("config:\n" + yaml);
  const std::string message = error_of(yaml);
  ASSERT_FALSE(message.empty()) << "no error";
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind("configs/x.yaml: ", 0), 0u) << message;
  for (const auto& piece : pieces)
    EXPECT_NE(message.find(piece), std::string::npos) << "'" << piece << "' not in: " << message;
}

TEST(MicrofacetSettings, IsotropicAnisotropicAndMasking) {
  const Settings g = parse("roughness: {model: ggx, alpha: 0.3}\n");
  ASSERT_TRUE(std::holds_alternative<roughness::Ggx>(g.fiber.roughness));
  EXPECT_EQ(std::get<roughness::Ggx>(g.fiber.roughness).alpha_long, 0.3);
  EXPECT_EQ(std::get<roughness::Ggx>(g.fiber.roughness).alpha_azim, 0.3);
  EXPECT_EQ(std::get<roughness::Ggx>(g.fiber.roughness).masking, Masking::None);  // the default

  const Settings b = parse("roughness: {model: beckmann, alpha: [0.1, 0.4], masking: smith_g1}\n");
  ASSERT_TRUE(std::holds_alternative<roughness::Beckmann>(b.fiber.roughness));
  EXPECT_EQ(std::get<roughness::Beckmann>(b.fiber.roughness).alpha_long, 0.1);
  EXPECT_EQ(std::get<roughness::Beckmann>(b.fiber.roughness).alpha_azim, 0.4);
  EXPECT_EQ(std::get<roughness::Beckmann>(b.fiber.roughness).masking, Masking::SmithG1);

  // A list of one is the isotropic alpha.
  EXPECT_EQ(std::get<roughness::Ggx>(parse("roughness: {model: ggx, alpha: [0.2]}\n").fiber.roughness).alpha_azim, 0.2);
  // masking: none is accepted (and means nothing) for every model.
  EXPECT_EQ(roughness::masking(parse("roughness: {model: gaussian, beta_long: 5, masking: none}\n").fiber.roughness),
            Masking::None);
}

TEST(MicrofacetSettings, RoundTripThroughToYaml) {
  for (const char* yaml : {"roughness: {model: ggx, alpha: 0.3}\n",
                           "roughness: {model: beckmann, alpha: [0.1, 0.4], masking: smith_g1}\n",
                           "roughness: {model: ggx, alpha: 1e-4, masking: smith_g1}\n",
                           "roughness: {model: gaussian, beta_long: 5}\n"}) {
    const Settings s = parse(yaml);
    const std::string text = to_yaml(s);
    EXPECT_EQ(parse(text), s) << text;
    const bool microfacet = std::holds_alternative<roughness::Ggx>(s.fiber.roughness) ||
                            std::holds_alternative<roughness::Beckmann>(s.fiber.roughness);
    EXPECT_EQ(text.find("alpha:") != std::string::npos, microfacet) << text;
    EXPECT_EQ(text.find("masking:") != std::string::npos, microfacet) << text;
    EXPECT_EQ(text.find("beta_long:") != std::string::npos, !microfacet) << text;
  }
}

TEST(MicrofacetSettingsErrors, Alpha) {
  expect_error("roughness: {model: ggx}\n", {"roughness.alpha is missing", "model ggx", "(0, 10]"});
  expect_error("roughness: {model: ggx, alpha: 0}\n", {"roughness.alpha = 0", "out of range", "(0, 10]"});
  expect_error("roughness: {model: beckmann, alpha: -0.1}\n", {"roughness.alpha = -0.1", "(0, 10]"});
  expect_error("roughness: {model: ggx, alpha: .nan}\n", {"roughness.alpha", "finite", "(0, 10]"});
  expect_error("roughness: {model: ggx, alpha: .inf}\n", {"roughness.alpha", "finite"});
  expect_error("roughness: {model: ggx, alpha: 11}\n", {"roughness.alpha = 11", "(0, 10]"});
  expect_error("roughness: {model: ggx, alpha: rough}\n", {"roughness.alpha = rough", "not a number"});
  expect_error("roughness: {model: ggx, alpha: [0.1, 0.2, 0.3]}\n",
               {"roughness.alpha = [0.1, 0.2, 0.3]", "3 entries", "[longitudinal, azimuthal]"});
  expect_error("roughness: {model: ggx, alpha: []}\n", {"roughness.alpha", "empty"});
  expect_error("roughness: {model: ggx, alpha: [0.1, 0]}\n", {"roughness.alpha[1] = 0", "(0, 10]"});
}

TEST(MicrofacetSettingsErrors, KeysOfTheOtherModels) {
  expect_error("roughness: {alpha: 0.3}\n",
               {"roughness.alpha = 0.3", "not allowed for model gaussian", "beckmann and ggx"});
  expect_error("roughness: {model: smooth, alpha: 0.3}\n", {"roughness.alpha", "model smooth"});
  expect_error("roughness: {model: ggx, alpha: 0.3, beta_long: 5}\n",
               {"roughness.beta_long = 5", "not allowed for model ggx", "take alpha"});
  expect_error("roughness: {model: beckmann, alpha: 0.3, beta_azim: 5}\n",
               {"roughness.beta_azim", "not allowed for model beckmann"});
  expect_error("roughness: {model: gaussian, beta_long: 5, masking: smith_g1}\n",
               {"roughness.masking = smith_g1", "not allowed for model gaussian", "beckmann and ggx"});
  expect_error("roughness: {model: exit_blur, masking: smith_g1}\n", {"roughness.masking", "exit_blur"});
  expect_error("roughness: {model: ggx, alpha: 0.3, masking: smith}\n",
               {"roughness.masking = smith", "none, smith_g1"});
  expect_error("roughness: {model: ggx, alpha: 0.3, masking: [smith_g1]}\n",
               {"roughness.masking", "is a list"});
  expect_error("roughness: {model: ggz, alpha: 0.3}\n", {"roughness.model = ggz", "beckmann, ggx"});
  expect_error("roughness: {model: ggx, alpa: 0.3}\n", {"unknown key roughness.alpa", "did you mean alpha?"});
}

}  // namespace
}  // namespace fiberlab::sim
