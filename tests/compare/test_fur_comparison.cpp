// Fur fibers (a medulla, docs/FUR.md) in the comparisons: the atlas sweeps
// `medulla` entries through the simulator's own parser, and a model, which
// has no medulla, is compared with the medullated fiber's lobes by p and
// predicts nothing in its `scattered` lobe.
#include <gtest/gtest.h>

#include "common/error.h"
#include "compare/atlas_config.h"
#include "tests/compare/compare_test_support.h"

namespace fiberlab::compare {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_atlas_config(yaml, "a.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(FurAtlas, MedullaSweepMakesOneFiberPerEntry) {
  const AtlasConfig c = parse_atlas_config(
      "photons: 10\nsweep: {roughness: [{model: smooth}], theta_i: 30,\n"
      "  medulla: [none, {radius: 0.5, sigma_s: 8, g: 0.4}]}\n",
      "t");
  ASSERT_EQ(c.fibers.size(), 2u);
  EXPECT_FALSE(c.fibers[0].settings.fiber.medulla.has_value());
  ASSERT_TRUE(c.fibers[1].settings.fiber.medulla.has_value());
  EXPECT_EQ(c.fibers[1].settings.fiber.medulla->radius, 0.5);
  EXPECT_EQ(c.fibers[1].settings.fiber.medulla->g, 0.4);
  EXPECT_EQ(c.fibers[1].medulla_index, 1);
  EXPECT_NE(c.fibers[1].label.find("medulla k 0.5"), std::string::npos) << c.fibers[1].label;
  const AtlasConfig shipped = load_atlas_config(FIBERLAB_SOURCE_DIR "/configs/atlas_fur.yaml");
  ASSERT_EQ(shipped.fibers.size(), 3u);
  EXPECT_FALSE(shipped.fibers[0].settings.fiber.medulla.has_value());
  EXPECT_EQ(shipped.fibers[2].settings.fiber.medulla->radius, 0.7);
  // Without the list: no medulla, labels as before.
  const AtlasConfig plain =
      parse_atlas_config("photons: 10\nsweep: {roughness: [{model: smooth}], theta_i: 30}\n", "t");
  EXPECT_EQ(plain.fibers[0].label.find("medulla"), std::string::npos);
}

TEST(FurAtlas, ErrorsNameTheMedullaEntry) {
  const std::string sweep = "photons: 10\nsweep: {roughness: [{model: smooth}], theta_i: 30, medulla: ";
  const std::string not_block = error_of(sweep + "[3]}\n");
  EXPECT_NE(not_block.find("sweep.medulla[0] = 3 must be none or a medulla block"), std::string::npos)
      << not_block;
  const std::string bad_radius = error_of(sweep + "[none, {radius: 2, sigma_s: 1}]}\n");
  EXPECT_NE(bad_radius.find("x medulla[1]"), std::string::npos) << bad_radius;
  EXPECT_NE(bad_radius.find("fiber.medulla.radius = 2 is out of range (must be in (0, 1)"),
            std::string::npos)
      << bad_radius;
}

// d'Eon's model against a smooth circle with a medulla: the lobes by p are
// compared as for any fiber, and the `scattered` lobe holds the
// simulation's scattered energy against the model's zero.
TEST(FurComparison, ModelsPredictNothingInTheScatteredLobe) {
  sim::Settings s = testing::circle(30.0, 20000, fiberlab::roughness::Smooth{});
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  Medulla m;
  m.radius = 0.5;
  m.sigma_s = 4.0;
  m.sigma_a = {0.0};
  m.eta = s.fiber.eta;
  s.fiber.medulla = m;
  const sim::ResultFile r = testing::run(s);
  ASSERT_EQ(r.lobes, 5);
  const std::vector<LobeComparison> lobes = testing::compare_with(r, "deon2011");
  ASSERT_EQ(lobes.size(), 5u);
  EXPECT_EQ(lobes[4].lobe, 4);
  EXPECT_EQ(lobes[4].model_energy, 0.0);
  EXPECT_GT(lobes[4].sim_energy, 0.2);
  EXPECT_GT(lobes[0].model_energy, 0.0);
}

}  // namespace
}  // namespace fiberlab::compare
