// The atlas config: the shipped files parse into the documented sweeps, and
// every fiber goes through the simulator's own parser (its settings are the
// simulator's, not a copy of its rules).
#include <gtest/gtest.h>

#include "common/error.h"
#include "common/units.h"
#include "compare/atlas_config.h"

namespace fiberlab::compare {
namespace {

TEST(AtlasConfig, ShippedConfigsParse) {
  const AtlasConfig small = load_atlas_config(FIBERLAB_SOURCE_DIR "/configs/atlas_small.yaml");
  EXPECT_EQ(small.fibers.size(), 2u);
  EXPECT_EQ(small.theta_i.size(), 2u);
  const AtlasConfig full = load_atlas_config(FIBERLAB_SOURCE_DIR "/configs/atlas.yaml");
  EXPECT_EQ(full.fibers.size(), 32u);  // 4 roughness x 2 absorption x 2 tilt x 2 eccentricity
  EXPECT_EQ(full.fibers[0].settings.source.theta_i.size(), 3u);
  // Roughness slowest, eccentricity fastest.
  EXPECT_EQ(full.fibers[1].settings.fiber.eccentricity, 0.85);
  EXPECT_EQ(full.fibers[8].roughness, 7.0);
  EXPECT_NEAR(full.fibers[8].settings.roughness.beta_long[0], deg_to_rad(7.0), 1e-15);
  // Melanin: three channels, sigma_a derived by the simulator.
  EXPECT_EQ(full.fibers[4].settings.fiber.sigma_a.size(), 3u);
  EXPECT_TRUE(full.fibers[4].settings.fiber.eumelanin.has_value());
}

TEST(AtlasConfig, ModelsDefaultToEveryRegisteredOne) {
  const AtlasConfig c = parse_atlas_config("photons: 10\nsweep: {roughness: [{model: smooth}], theta_i: 30}\n", "t");
  EXPECT_GE(c.models.size(), 4u);
  EXPECT_EQ(c.models.front(), "exact");
  EXPECT_EQ(c.fibers.size(), 1u);
  EXPECT_EQ(c.fibers[0].settings.photons, 10u);
}

TEST(AtlasConfig, ErrorsNameTheEntry) {
  auto error_of = [](const std::string& yaml) {
    try {
      parse_atlas_config(yaml, "a.yaml");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("photons: 10\nsweep: {roughness: [{model: smooth}], theta_i: 30, scale_tilt: [0, 50]}\n")
                .find("scale_tilt[1]"),
            std::string::npos);
  EXPECT_NE(error_of("photons: 10\nsweep: {roughness: [], theta_i: 30}\n").find("sweep.roughness is empty"),
            std::string::npos);
  EXPECT_NE(error_of("photons: 0\nsweep: {roughness: [{model: smooth}], theta_i: 30}\n").find("photons"),
            std::string::npos);
  EXPECT_NE(error_of("photons: 10\nfit: {max_iterations: -1}\nsweep: {roughness: [{model: smooth}], theta_i: 30}\n")
                .find("fit.max_iterations"),
            std::string::npos);
}

}  // namespace
}  // namespace fiberlab::compare
