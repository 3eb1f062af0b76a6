// The atlas checkpoint (compare/atlas_checkpoint.h): a fiber read back is
// the fiber written, every field bit for bit (the list of fields here is the
// test's own, not the code's, so a field the writer forgets is caught), the
// fit's parameters rebuilt as the fit made them; the config identity follows
// what changes the results and nothing else; with fit.per_lobe, each lobe's
// own fit is read back too. The end-to-end interrupt and resume through the
// program: tests/cli/atlas_resume.sh (with per_lobe: atlas_per_lobe.sh).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "analytic/model_registry.h"
#include "common/error.h"
#include "compare/atlas.h"
#include "compare/atlas_checkpoint.h"
#include "compare/atlas_config.h"
#include "tests/unique_temp_dir.h"

namespace fiberlab::compare {
namespace {

const char* kConfig =
    "photons: 3000\nseed: 4\ntally: {n_theta: 8, n_phi: 8, lobes: 3}\n"
    "sweep:\n  roughness: [{model: exit_blur, beta_long: 8, beta_azim: 15}, {model: exit_blur, beta_long: 9, beta_azim: 12}]\n"
    "  absorption: [{sigma_a: [0.1, 0.3]}]\n  theta_i: [20, 50]\n"
    "models: [exact, deon2011]\nmodel_parameters: {deon2011: {quadrature_order: 12}}\nfit: {max_iterations: 2}\n";

// Bitwise, so that NaN equals NaN and -0 differs from 0.
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_bits(a[i], b[i])) return false;
  return true;
}

void expect_same(const ChiSquare& a, const ChiSquare& b, const std::string& what) {
  EXPECT_TRUE(same_bits(a.chi2, b.chi2)) << what;
  EXPECT_EQ(a.dof, b.dof) << what;
}

void expect_same(const LobeComparison& a, const LobeComparison& b, const std::string& what) {
  EXPECT_EQ(a.k, b.k) << what;
  EXPECT_EQ(a.lobe, b.lobe) << what;
  EXPECT_EQ(a.channel, b.channel) << what;
  for (auto [x, y, name] : {std::tuple{a.theta_i, b.theta_i, "theta_i"}, {a.phi_i, b.phi_i, "phi_i"},
                            {a.sim_energy, b.sim_energy, "sim_energy"}, {a.sim_error, b.sim_error, "sim_error"},
                            {a.model_energy, b.model_energy, "model_energy"}, {a.energy_z, b.energy_z, "energy_z"},
                            {a.rest_sim, b.rest_sim, "rest_sim"}, {a.rest_model, b.rest_model, "rest_model"},
                            {a.l1, b.l1, "l1"}, {a.peak_sim, b.peak_sim, "peak_sim"},
                            {a.peak_model, b.peak_model, "peak_model"}, {a.centroid_sim, b.centroid_sim, "centroid_sim"},
                            {a.centroid_sim_error, b.centroid_sim_error, "centroid_sim_error"},
                            {a.centroid_model, b.centroid_model, "centroid_model"},
                            {a.alpha_model, b.alpha_model, "alpha_model"},
                            {a.measured_shift, b.measured_shift, "measured_shift"}})
    EXPECT_TRUE(same_bits(x, y)) << what << "." << name << ": " << x << " vs " << y;
  expect_same(a.bins, b.bins, what + ".bins");
  expect_same(a.theta_marginal, b.theta_marginal, what + ".theta_marginal");
  expect_same(a.phi_marginal, b.phi_marginal, what + ".phi_marginal");
  EXPECT_EQ(a.compared_bins, b.compared_bins) << what;
  EXPECT_EQ(a.judged, b.judged) << what;
}

void expect_same(const std::vector<LobeComparison>& a, const std::vector<LobeComparison>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) expect_same(a[i], b[i], what + "[" + std::to_string(i) + "]");
}

void expect_same(const FitResult& x, const FitResult& y, const std::string& model, const std::string& what);

void expect_same(const AtlasModelResult& a, const AtlasModelResult& b, const std::string& what) {
  EXPECT_EQ(a.model, b.model) << what;
  EXPECT_EQ(a.status, b.status) << what;
  EXPECT_EQ(a.applicable, b.applicable) << what;
  EXPECT_EQ(a.fitted, b.fitted) << what;
  EXPECT_EQ(a.params_before, b.params_before) << what;
  EXPECT_EQ(a.params_after, b.params_after) << what;
  EXPECT_TRUE(same_bits(a.seconds, b.seconds)) << what;
  expect_same(a.before, b.before, what + ".before");
  expect_same(a.after, b.after, what + ".after");
  expect_same(a.fit, b.fit, a.model, what + ".fit");
  EXPECT_EQ(a.lobe_fit_status, b.lobe_fit_status) << what;
  EXPECT_EQ(a.lobe_fit_lines, b.lobe_fit_lines) << what;
  expect_same(a.after_lobe_fit, b.after_lobe_fit, what + ".after_lobe_fit");
  ASSERT_EQ(a.lobe_fits.size(), b.lobe_fits.size()) << what;
  for (std::size_t j = 0; j < a.lobe_fits.size(); ++j) {
    EXPECT_EQ(a.lobe_fits[j].lobe, b.lobe_fits[j].lobe) << what;
    expect_same(a.lobe_fits[j].fit, b.lobe_fits[j].fit, a.model, what + ".lobe_fits[" + std::to_string(j) + "]");
  }
}

void expect_same(const FitResult& x, const FitResult& y, const std::string& model, const std::string& what) {
  EXPECT_EQ(x.keys, y.keys) << what;
  EXPECT_TRUE(same_bits(x.start, y.start)) << what;
  EXPECT_TRUE(same_bits(x.value, y.value)) << what;
  EXPECT_TRUE(same_bits(x.error, y.error)) << what;
  EXPECT_TRUE(same_bits(x.error_unscaled, y.error_unscaled)) << what;
  EXPECT_EQ(x.at_bound, y.at_bound) << what;
  EXPECT_TRUE(same_bits(x.chi2_start, y.chi2_start)) << what;
  EXPECT_TRUE(same_bits(x.chi2, y.chi2)) << what;
  EXPECT_EQ(x.residuals, y.residuals) << what;
  EXPECT_EQ(x.dof, y.dof) << what;
  EXPECT_EQ(x.iterations, y.iterations) << what;
  EXPECT_EQ(x.evaluations, y.evaluations) << what;
  EXPECT_EQ(x.converged, y.converged) << what;
  // The parameters at the minimum: rebuilt, and the same model.
  EXPECT_EQ(analytic::describe_params(model, x.params), analytic::describe_params(model, y.params)) << what;
}

void expect_same(const AtlasFiberResult& a, const AtlasFiberResult& b, const std::string& what) {
  EXPECT_EQ(a.fiber.label, b.fiber.label) << what;
  EXPECT_TRUE(a.fiber.settings == b.fiber.settings) << what;
  EXPECT_TRUE(same_bits(a.theta_i, b.theta_i)) << what;
  EXPECT_EQ(a.lobes, b.lobes) << what;
  EXPECT_EQ(a.channels, b.channels) << what;
  EXPECT_TRUE(same_bits(a.sim_energy, b.sim_energy)) << what;
  EXPECT_TRUE(same_bits(a.sim_error, b.sim_error)) << what;
  EXPECT_EQ(a.photons, b.photons) << what;
  EXPECT_TRUE(same_bits(a.sim_seconds, b.sim_seconds)) << what;
  EXPECT_TRUE(same_bits(a.fit_seconds, b.fit_seconds)) << what;
  ASSERT_EQ(a.models.size(), b.models.size()) << what;
  for (std::size_t m = 0; m < a.models.size(); ++m) expect_same(a.models[m], b.models[m], what + "." + a.models[m].model);
}

class AtlasCheckpointTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test_support::unique_temp_dir("fiberlab_atlas_checkpoint"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::filesystem::path dir_;
};

TEST_F(AtlasCheckpointTest, AFiberReadBackIsTheFiberWrittenBitForBit) {
  AtlasRunSetup setup{"t.yaml", kConfig, "2500", "t.h5", "", "fiberlab atlas t.yaml -o t.h5 --photons 2500"};
  const AtlasConfig config = atlas_config_of(setup);
  ASSERT_EQ(config.fibers.size(), 2u);
  EXPECT_EQ(config.fibers[0].settings.photons, 2500u);  // --photons applied
  AtlasControl control;
  control.threads = 1;
  std::vector<AtlasFiberResult> fibers{run_atlas_fiber(config, 0, control)};
  ASSERT_TRUE(fibers[0].models[1].fitted) << fibers[0].models[1].status;  // deon2011: a fit to restore
  ASSERT_FALSE(fibers[0].models[0].fitted);                                // exact: none
  const std::string file = path("t.checkpoint.h5");
  // One fiber of two saved, then both (the file rewritten in place).
  write_atlas_checkpoint(file, setup, config, fibers);
  AtlasCheckpoint one = read_atlas_checkpoint(file);
  ASSERT_EQ(one.fibers.size(), 1u);
  expect_same(fibers[0], one.fibers[0], "fiber 1 of 1");
  fibers.push_back(run_atlas_fiber(config, 1, control));
  write_atlas_checkpoint(file, setup, config, fibers);
  const AtlasCheckpoint two = read_atlas_checkpoint(file);
  ASSERT_EQ(two.fibers.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) expect_same(fibers[i], two.fibers[i], "fiber " + std::to_string(i + 1));
  EXPECT_EQ(two.setup.config_path, setup.config_path);
  EXPECT_EQ(two.setup.config_yaml, setup.config_yaml);
  EXPECT_EQ(two.setup.photons_flag, setup.photons_flag);
  EXPECT_EQ(two.setup.output_name, setup.output_name);
  EXPECT_EQ(two.setup.command, setup.command);
  EXPECT_EQ(atlas_config_identity(two.config), atlas_config_identity(config));
  // Nothing but the checkpoint in the folder (no temporary left).
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), {}), 1);
}

// fit.per_lobe: each lobe's own fit (here R and p>=2 of fit.lobes) and its
// comparison rows read back as written, from the checkpoint and from the
// bytes one MPI rank sends another; the parameters of each lobe fit rebuilt
// from the joint fit's.
TEST_F(AtlasCheckpointTest, PerLobeFitsReadBackToo) {
  std::string yaml = kConfig;
  yaml.replace(yaml.find("max_iterations: 2"), 17, "max_iterations: 2, per_lobe: true, lobes: [R, p>=2]");
  AtlasRunSetup setup{"p.yaml", yaml, "", "p.h5", "", "fiberlab atlas p.yaml -o p.h5"};
  const AtlasConfig config = atlas_config_of(setup);
  ASSERT_TRUE(config.per_lobe);
  AtlasControl control;
  control.threads = 1;
  const std::vector<AtlasFiberResult> fibers{run_atlas_fiber(config, 0, control)};
  const AtlasModelResult& deon = fibers[0].models[1];
  ASSERT_EQ(deon.lobe_fits.size(), 2u) << deon.lobe_fit_status;
  EXPECT_EQ(deon.lobe_fits[0].lobe, 0);
  EXPECT_EQ(deon.lobe_fits[1].lobe, 2);
  EXPECT_EQ(deon.lobe_fits[1].fit.keys, (std::vector<std::string>{"beta_long[2]", "beta_azim[2]", "alpha[2]"}));
  EXPECT_FALSE(deon.after_lobe_fit.empty());
  for (const LobeComparison& c : deon.after_lobe_fit) EXPECT_TRUE(c.lobe == 0 || c.lobe == 2) << c.lobe;
  EXPECT_EQ(fibers[0].models[0].lobe_fit_status,
            "not fitted lobe by lobe: its parameter table marks no parameter free");
  write_atlas_checkpoint(path("p.checkpoint.h5"), setup, config, fibers);
  const AtlasCheckpoint c = read_atlas_checkpoint(path("p.checkpoint.h5"));
  ASSERT_EQ(c.fibers.size(), 1u);
  expect_same(fibers[0], c.fibers[0], "fiber 1");
  const auto bytes = pack_atlas_fiber(config, 0, fibers[0], path("pack.h5"));
  expect_same(fibers[0], unpack_atlas_fiber(config, 0, bytes, path("unpack.h5")), "fiber 1 (packed)");
}

// No model fitted (fit.max_iterations 0) and a model not applicable (an
// elliptical fiber for deon2011): nothing of either kind to store, and still
// read back as written.
TEST_F(AtlasCheckpointTest, FibersWithoutFitsReadBackToo) {
  std::string yaml = kConfig;
  yaml.replace(yaml.find("max_iterations: 2"), 17, "max_iterations: 0");
  yaml.replace(yaml.find("theta_i: [20, 50]"), 17, "theta_i: [20, 50]\n  eccentricity: [1, 0.9]");
  AtlasRunSetup setup{"u.yaml", yaml, "", "u.h5", "/tmp/r", "fiberlab atlas u.yaml -o u.h5 --report /tmp/r"};
  const AtlasConfig config = atlas_config_of(setup);
  ASSERT_EQ(config.fibers.size(), 4u);
  AtlasControl control;
  control.threads = 1;
  const std::vector<AtlasFiberResult> fibers{run_atlas_fiber(config, 0, control), run_atlas_fiber(config, 1, control)};
  ASSERT_FALSE(fibers[1].models[1].applicable) << fibers[1].models[1].status;
  ASSERT_FALSE(fibers[0].models[1].fitted) << fibers[0].models[1].status;
  write_atlas_checkpoint(path("u.checkpoint.h5"), setup, config, fibers);
  const AtlasCheckpoint c = read_atlas_checkpoint(path("u.checkpoint.h5"));
  ASSERT_EQ(c.fibers.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) expect_same(fibers[i], c.fibers[i], "fiber " + std::to_string(i + 1));
  EXPECT_EQ(c.setup.report_dir, "/tmp/r");
}

TEST(AtlasCheckpoint, IdentityFollowsWhatChangesTheResults) {
  const std::string base = atlas_config_identity(parse_atlas_config(kConfig, "a"));
  // Comments, key order and the file's name change nothing, nor do the
  // defaults written out.
  std::string defaults = kConfig;
  defaults.replace(defaults.find("max_iterations: 2"), 17, "max_iterations: 2, per_lobe: false");
  EXPECT_EQ(atlas_config_identity(parse_atlas_config(defaults, "e")), base);
  std::string reordered = std::string("# a comment\nseed: 4\n") + kConfig;
  reordered.erase(reordered.find("seed: 4\ntally"), 8);
  EXPECT_EQ(atlas_config_identity(parse_atlas_config(reordered, "b")), base);
  // Each of these changes the results, and the identity.
  for (auto [from, to] : {std::pair{"photons: 3000", "photons: 3001"}, {"seed: 4", "seed: 5"},
                          {"lobes: 3", "lobes: 4"}, {"beta_long: 9", "beta_long: 9.5"},
                          {"[0.1, 0.3]", "[0.1, 0.31]"}, {"[20, 50]", "[20, 51]"},
                          {"models: [exact, deon2011]", "models: [deon2011]"},
                          {"quadrature_order: 12", "quadrature_order: 13"},
                          {"max_iterations: 2", "max_iterations: 3"},
                          {"max_iterations: 2", "max_iterations: 2, per_lobe: true"},
                          {"max_iterations: 2", "max_iterations: 2, lobes: [TT]"}}) {
    std::string changed = kConfig;
    const auto at = changed.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    changed.replace(at, std::strlen(from), to);
    EXPECT_NE(atlas_config_identity(parse_atlas_config(changed, "c")), base) << from << " -> " << to;
  }
  AtlasConfig photons = parse_atlas_config(kConfig, "d");
  override_photons(photons, "4000");
  EXPECT_NE(atlas_config_identity(photons), base);
}

TEST_F(AtlasCheckpointTest, ADifferentConfigIsRefusedNamingBoth) {
  AtlasRunSetup setup{"t.yaml", kConfig, "", "t.h5", "", "fiberlab atlas t.yaml -o t.h5"};
  const AtlasConfig config = atlas_config_of(setup);
  write_atlas_checkpoint(path("t.checkpoint.h5"), setup, config, {});
  const AtlasCheckpoint c = read_atlas_checkpoint(path("t.checkpoint.h5"));
  EXPECT_TRUE(c.fibers.empty());
  EXPECT_NO_THROW(check_same_atlas_config(c, parse_atlas_config(kConfig, "same.yaml"), "t.checkpoint.h5"));
  std::string changed = kConfig;
  changed.replace(changed.find("seed: 4"), 7, "seed: 6");
  try {
    check_same_atlas_config(c, parse_atlas_config(changed, "other.yaml"), "t.checkpoint.h5");
    FAIL() << "a different seed was accepted";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find("t.checkpoint.h5: the config other.yaml differs"), std::string::npos) << m;
    EXPECT_NE(m.find("\"seed: 6\" where the checkpoint has \"seed: 4\""), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace fiberlab::compare
